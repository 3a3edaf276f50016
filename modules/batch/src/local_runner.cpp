// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/local_runner.h>
#include <msf/batch/subprocess.h>
#include <msf/common/exceptions.h>

#include <chrono>
#include <cstdio>
#include <deque>
#include <memory>
#include <thread>

namespace msf {

namespace {

struct Running {
  BatchTask task;
  int attempt = 1;
  double memory_mb = 0;
  std::unique_ptr<Subprocess> process;
};

std::string taskLog(const BatchPlan& plan, const BatchTask& task) {
  std::string name = task.text();
  for (char& c : name)
    if (c == ':')
      c = '_';
  return plan.logDir() + "/task_" + name + ".log";
}

} // namespace

LocalRunner::LocalRunner(const BatchPlan& plan, int parallel, double memory_mb)
    : plan_(plan), parallel_(parallel), memory_mb_(memory_mb) {
  if (parallel_ < 1)
    throw InvalidInputError("-local: at least 1 task at a time, got " + std::to_string(parallel_));
}

bool LocalRunner::runStage(const std::vector<BatchTask>& tasks) {
  std::deque<std::pair<BatchTask, int>> waiting; // task, attempt
  for (const BatchTask& t : tasks)
    waiting.emplace_back(t, 1);
  std::vector<Running> running;
  double memory_in_use = 0;
  bool failed = false;
  const auto memoryOf = [&](const BatchTask& t) {
    return t.kind == BatchTask::Kind::Drive ? plan_.predictedMb(t.index) : 0.0;
  };
  while (!waiting.empty() || !running.empty()) {
    // Start what fits: a slot, and memory unless nothing runs (a drive larger than the budget runs alone).
    while (!failed && !waiting.empty() && static_cast<int>(running.size()) < parallel_ &&
           (running.empty() || memory_in_use + memoryOf(waiting.front().first) <= memory_mb_)) {
      auto [task, attempt] = waiting.front();
      waiting.pop_front();
      Running r{task, attempt, memoryOf(task), nullptr};
      r.process = std::make_unique<Subprocess>(batchTaskCommand(plan_, task), taskLog(plan_, task));
      memory_in_use += r.memory_mb;
      running.push_back(std::move(r));
    }
    bool ended = false;
    for (std::size_t k = 0; k < running.size(); ++k) {
      int status = 0;
      if (!running[k].process->finished(status))
        continue;
      Running r = std::move(running[k]);
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(k--));
      memory_in_use -= r.memory_mb;
      ended = true;
      if (status == 0)
        continue;
      if (r.attempt < plan_.options().max_attempts) {
        std::printf("task %s failed (status %d), attempt %d of %d: run again\n", r.task.text().c_str(), status,
                    r.attempt, plan_.options().max_attempts);
        waiting.emplace_back(r.task, r.attempt + 1);
      } else {
        std::fprintf(stderr, "task %s failed (status %d) on its last attempt (%d): see %s\n", r.task.text().c_str(),
                     status, r.attempt, taskLog(plan_, r.task).c_str());
        failed = true;
      }
    }
    if (failed && running.empty())
      break;
    if (!ended)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return !failed;
}

bool LocalRunner::run() {
  if (plan_.mapDone())
    return true;
  std::vector<BatchTask> drives, merges, meshes;
  for (std::size_t i = 0; i < plan_.drives().size(); ++i)
    if (!plan_.driveDone(i))
      drives.push_back({BatchTask::Kind::Drive, i});
  for (int k = 0; k < plan_.options().merge_tasks; ++k) {
    merges.push_back({BatchTask::Kind::Merge, static_cast<std::size_t>(k)});
    meshes.push_back({BatchTask::Kind::Mesh, static_cast<std::size_t>(k)});
  }
  return runStage(drives) && runStage(merges) && runStage(meshes) && runStage({{BatchTask::Kind::Finish, 0}});
}

} // namespace msf
