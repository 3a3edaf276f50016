// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/slurm_jobs.h>
#include <msf/batch/subprocess.h>
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

namespace msf {

namespace fs = std::filesystem;

namespace {

const char* kindName(BatchTask::Kind kind) {
  switch (kind) {
  case BatchTask::Kind::Drive:
    return "drive";
  case BatchTask::Kind::Merge:
    return "merge";
  case BatchTask::Kind::Mesh:
    return "mesh";
  case BatchTask::Kind::Finish:
    break;
  }
  return "finish";
}

std::string arrayList(const std::vector<std::size_t>& indices) {
  std::string list;
  for (const std::size_t i : indices)
    list += (list.empty() ? "" : ",") + std::to_string(i);
  return list;
}

/// Writes the stage's script to OUT/jobs/NAME.sbatch and submits it after `after` (job ids).
std::string submit(const BatchPlan& plan, const std::string& name, const std::string& script,
                   const std::vector<std::string>& after) {
  const std::string path = plan.jobDir() + "/" + name + ".sbatch";
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << script;
    if (!out.flush())
      throw IOError("cannot write '" + path + "'");
  });
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  if (!after.empty()) {
    std::string dependency = "--dependency=afterok";
    for (const std::string& id : after)
      dependency += ":" + id;
    argv.insert(argv.end(), {dependency, "--kill-on-invalid-dep=yes"});
  }
  argv.push_back(path);
  const CommandOutput r = captureCommand(argv);
  std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
  if (r.status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw IOError("sbatch did not take '" + path + "' (status " + std::to_string(r.status) + "): " + r.err + r.out);
  return id;
}

} // namespace

std::vector<std::string> SlurmSubmission::all() const {
  std::vector<std::string> ids = drive_jobs;
  for (const std::string& id : {merge_job, mesh_job, finish_job})
    if (!id.empty())
      ids.push_back(id);
  return ids;
}

std::string slurmStageScript(const BatchPlan& plan, BatchTask::Kind kind, const std::vector<std::size_t>& indices,
                             std::size_t memory_mb, int cpus, const SlurmOptions& options) {
  const std::string name = kindName(kind);
  const bool array = kind != BatchTask::Kind::Finish;
  const int attempts = plan.options().max_attempts;
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# The " << name << " stage of the batch in " << plan.out() << ", written by msf_batch (docs/batch.md).\n"
    << "#SBATCH --job-name=msf_" << name << "\n";
  if (array)
    s << "#SBATCH --array=" << arrayList(indices) << "\n";
  s << "#SBATCH --cpus-per-task=" << cpus << "\n"
    << "#SBATCH --mem=" << memory_mb << "M\n"
    << "#SBATCH --requeue\n"
    << "#SBATCH --open-mode=append\n"
    << "#SBATCH --output=" << plan.logDir() << "/slurm_" << name << (array ? "_%a" : "") << ".out\n";
  if (!options.partition.empty())
    s << "#SBATCH --partition=" << options.partition << "\n";
  if (options.time_min > 0)
    s << "#SBATCH --time=" << options.time_min << "\n";
  s << "task=" << name << (array ? ":$SLURM_ARRAY_TASK_ID" : "") << "\n"
    << shellQuote({plan.options().batch, "-o", plan.out(), "-run"}) << " \"$task\"\n"
    << "status=$?\n"
    << "restarts=${SLURM_RESTART_COUNT:-0}\n"
    << "# A failed attempt is requeued: the task starts again from nothing (a finished one does nothing).\n"
    << "if [ \"$status\" -ne 0 ] && [ \"$restarts\" -lt " << attempts - 1 << " ]; then\n"
    << "  echo \"msf_batch: task $task failed with status $status on attempt $((restarts + 1)) of " << attempts
    << ": requeued\"\n"
    << "  job=${SLURM_ARRAY_JOB_ID:+${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}}\n"
    << "  scontrol requeue \"${job:-$SLURM_JOB_ID}\" && sleep 600\n"
    << "fi\n"
    << "exit \"$status\"\n";
  return s.str();
}

SlurmSubmission submitToSlurm(const BatchPlan& plan, const SlurmOptions& options) {
  SlurmSubmission jobs;
  if (plan.mapDone())
    return jobs;
  // One array per memory request, so that each drive asks for what its prediction says.
  std::map<std::size_t, std::vector<std::size_t>> by_memory;
  for (std::size_t i = 0; i < plan.drives().size(); ++i)
    if (!plan.driveDone(i))
      by_memory[plan.requestMb(i)].push_back(i);
  for (const auto& [memory, drives] : by_memory)
    jobs.drive_jobs.push_back(submit(plan, "drives_" + std::to_string(memory) + "M",
                                     slurmStageScript(plan, BatchTask::Kind::Drive, drives, memory,
                                                      plan.options().cpus, options),
                                     {}));
  std::vector<std::size_t> shares;
  for (int k = 0; k < plan.options().merge_tasks; ++k)
    shares.push_back(static_cast<std::size_t>(k));
  jobs.merge_job = submit(plan, "merge",
                          slurmStageScript(plan, BatchTask::Kind::Merge, shares, kMergeTaskMemoryMb, 1, options),
                          jobs.drive_jobs);
  jobs.mesh_job = submit(plan, "mesh",
                         slurmStageScript(plan, BatchTask::Kind::Mesh, shares, kMergeTaskMemoryMb, 1, options),
                         {jobs.merge_job});
  jobs.finish_job = submit(plan, "finish",
                           slurmStageScript(plan, BatchTask::Kind::Finish, {}, kFinishTaskMemoryMb, 1, options),
                           {jobs.mesh_job});
  std::ofstream ids(plan.jobDir() + "/submitted.txt", std::ios::app);
  for (const std::string& id : jobs.all())
    ids << id << "\n";
  return jobs;
}

bool waitForSlurm(const SlurmSubmission& jobs, double timeout_s, double poll_s) {
  std::set<std::string> waiting(jobs.drive_jobs.begin(), jobs.drive_jobs.end());
  for (const std::string& id : {jobs.merge_job, jobs.mesh_job, jobs.finish_job})
    if (!id.empty())
      waiting.insert(id);
  const auto start = std::chrono::steady_clock::now();
  int failures = 0;
  while (!waiting.empty()) {
    // %A: an array's job id for each of its tasks, a job's own id otherwise.
    const CommandOutput r = captureCommand({"squeue", "-h", "-o", "%A"});
    if (r.status != 0) {
      if (++failures >= 10)
        throw IOError("squeue failed 10 times in a row (status " + std::to_string(r.status) + "): " + r.err);
    } else {
      failures = 0;
      std::set<std::string> queued;
      std::stringstream ss(r.out);
      for (std::string id; ss >> id;)
        queued.insert(id);
      std::set<std::string> still;
      for (const std::string& id : waiting)
        if (queued.count(id))
          still.insert(id);
      waiting = still;
      if (waiting.empty())
        return true;
    }
    if (timeout_s > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s)
      return false;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
  return true;
}

} // namespace msf
