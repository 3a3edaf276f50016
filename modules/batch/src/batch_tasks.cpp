// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/batch_tasks.h>
#include <msf/batch/subprocess.h>
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/json_text.h>
#include <msf/common/output_folder.h>
#include <msf/reconstruction/store_merge.h>
#include <msf/reconstruction/streaming_map.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

namespace msf {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void appendLine(const std::string& path, const std::string& line) {
  std::ofstream out(path, std::ios::app);
  out << line << "\n";
  if (!out.flush())
    throw IOError("cannot write '" + path + "'");
}

/// Where this attempt runs, for the drive's log: the time, the host, and Slurm's task and restart.
std::string attemptHeader() {
  char host[256] = "?";
  ::gethostname(host, sizeof host - 1);
  char when[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  std::string slurm;
  if (const char* job = std::getenv("SLURM_ARRAY_JOB_ID"))
    slurm = std::string(", Slurm job ") + job + "_" + (std::getenv("SLURM_ARRAY_TASK_ID") ? std::getenv("SLURM_ARRAY_TASK_ID") : "?") +
            " restart " + (std::getenv("SLURM_RESTART_COUNT") ? std::getenv("SLURM_RESTART_COUNT") : "0");
  return std::string("== msf_batch: attempt at ") + when + " on " + host + slurm;
}

/// Key-value statistics of a merge or mesh share, read back by the finish.
using Figures = std::map<std::string, double>;
void writeFigures(const std::string& path, const Figures& figures) {
  std::ostringstream ss;
  ss.precision(12);
  for (const auto& [key, value] : figures)
    ss << key << " " << value << "\n";
  fs::create_directories(fs::path(path).parent_path());
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << ss.str();
    if (!out.flush())
      throw IOError("cannot write '" + path + "'");
  });
}
Figures readFigures(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in)
    throw IOError(what + " has not finished: '" + path + "' is missing");
  Figures figures;
  std::string key;
  double value = 0;
  while (in >> key >> value)
    figures[key] = value;
  return figures;
}

std::string sharePath(const BatchPlan& plan, const char* kind, std::size_t share) {
  return plan.mergeDir() + "/stats/" + kind + "_" + std::to_string(share) + ".txt";
}

/// The drives' stores, once every drive is done: the merge reads committed drives only.
std::vector<std::string> doneStores(const BatchPlan& plan) {
  std::vector<std::string> stores, missing;
  for (std::size_t i = 0; i < plan.drives().size(); ++i) {
    stores.push_back(plan.driveDir(i));
    if (!plan.driveDone(i))
      missing.push_back(plan.drives()[i].name);
  }
  if (!missing.empty()) {
    std::string names;
    for (const std::string& n : missing)
      names += (names.empty() ? "" : ", ") + n;
    throw InvalidInputError("the merge reads finished drives only, and " + std::to_string(missing.size()) + " of " +
                            std::to_string(stores.size()) + " are not done for this plan: " + names +
                            " (their logs are in " + plan.logDir() + ")");
  }
  return stores;
}

StoreMerge openMerge(const BatchPlan& plan) {
  StoreMerge::Config config;
  config.max_weight = plan.pipelineConfig().integrator.max_weight;
  return StoreMerge(doneStores(plan), config);
}

int runDrive(const BatchPlan& plan, std::size_t i) {
  const Drive& drive = plan.drives().at(i);
  if (plan.driveDone(i)) {
    std::printf("drive %s: done (%s is committed for this request): nothing to do\n", drive.name.c_str(),
                plan.driveDir(i).c_str());
    return 0;
  }
  plan.clearDriveDone(i);
  const std::vector<std::string> command = plan.reconstructCommand(i);
  const std::string log = plan.driveLog(i);
  appendLine(log, attemptHeader() + "\n== " + shellQuote(command));
  const auto start = Clock::now();
  const std::time_t started = std::time(nullptr);
  int status = Subprocess(command, log).wait();
  const double seconds = secondsSince(start);
  appendLine(log, "== msf_batch: msf_reconstruct ended with status " + std::to_string(status) + " after " +
                      std::to_string(seconds) + " s");
  appendLine(plan.logDir() + "/" + drive.name + ".times",
             std::to_string(started) + " " + std::to_string(seconds) + " " + std::to_string(status));
  std::error_code e;
  if (status == 0 && !fs::is_regular_file(plan.driveDir(i) + "/tsdf/index.txt", e)) {
    std::fprintf(stderr, "drive %s: msf_reconstruct wrote no TSDF store (tsdf/index.txt)\n", drive.name.c_str());
    status = 1;
  }
  if (status != 0) {
    std::fprintf(stderr, "drive %s: msf_reconstruct ended with status %d (log: %s)\n", drive.name.c_str(), status,
                 log.c_str());
    return status;
  }
  plan.markDriveDone(i);
  std::printf("drive %s: done in %.1f s\n", drive.name.c_str(), seconds);
  return 0;
}

int runMerge(const BatchPlan& plan, std::size_t share) {
  if (plan.mapDone()) {
    std::printf("merge share %zu: the map is done: nothing to do\n", share);
    return 0;
  }
  const StoreMerge merge = openMerge(plan);
  const std::vector<GridIndex> tiles = merge.tilesOfTask(static_cast<int>(share), plan.options().merge_tasks);
  const StoreMerge::Stats s = merge.merge(tiles, merge.outputStore(plan.mergeDir()));
  writeFigures(sharePath(plan, "merge", share),
               {{"tiles", double(s.tiles)}, {"tiles_shared", double(s.tiles_shared)}, {"blocks", double(s.blocks)},
                {"blocks_shared", double(s.blocks_shared)}, {"voxels_shared", double(s.voxels_shared)},
                {"voxels_capped", double(s.voxels_capped)}, {"ms", s.ms}});
  std::printf("merge share %zu: %zu tiles (%zu held by several drives), %zu blocks in %.0f ms\n", share, s.tiles,
              s.tiles_shared, s.blocks, s.ms);
  return 0;
}

int runMesh(const BatchPlan& plan, std::size_t share) {
  if (plan.mapDone()) {
    std::printf("mesh share %zu: the map is done: nothing to do\n", share);
    return 0;
  }
  const auto start = Clock::now();
  const StoreMerge merge = openMerge(plan);
  for (int k = 0; k < plan.options().merge_tasks; ++k)
    readFigures(sharePath(plan, "merge", static_cast<std::size_t>(k)), "merge share " + std::to_string(k));
  TsdfStore merged = merge.outputStore(plan.mergeDir());
  merge.writeIndex(merged); // every share writes the same index
  const std::string tiles_dir = plan.mergeDir() + "/tiles";
  fs::create_directories(tiles_dir);
  const std::vector<GridIndex> tiles = merge.tilesOfTask(static_cast<int>(share), plan.options().merge_tasks);
  const std::size_t triangles = StreamingMap::meshTiles(merged, plan.pipelineConfig().mesher, tiles, tiles_dir);
  const double ms = secondsSince(start) * 1000.0;
  writeFigures(sharePath(plan, "mesh", share), {{"tiles", double(tiles.size())}, {"triangles", double(triangles)}, {"ms", ms}});
  std::printf("mesh share %zu: %zu tiles, %zu triangles in %.0f ms\n", share, tiles.size(), triangles, ms);
  return 0;
}

/// The drives' attempts and times (OUT/logs/NAME.times: start, seconds, status per attempt).
std::string drivesJson(const BatchPlan& plan) {
  std::ostringstream s;
  for (std::size_t i = 0; i < plan.drives().size(); ++i) {
    const Drive& d = plan.drives()[i];
    std::ifstream in(plan.logDir() + "/" + d.name + ".times");
    long long started = 0;
    double seconds = 0, total = 0, last = 0;
    int status = 0, attempts = 0;
    while (in >> started >> seconds >> status) {
      ++attempts;
      total += seconds;
      last = seconds;
    }
    s << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(d.name) << ", \"dataset\": " << jsonString(d.dataset)
      << ", \"predicted_memory_mb\": " << plan.predictedMb(i) << ", \"requested_memory_mb\": " << plan.requestMb(i)
      << ", \"attempts\": " << attempts << ", \"reconstruct_s\": " << last << ", \"reconstruct_s_all_attempts\": " << total
      << "}";
  }
  return s.str();
}

/// Hard links (same file system: OUT/merge and OUT/map's staging are both in OUT), else a copy.
void linkInto(const fs::path& from, const fs::path& to) {
  std::error_code e;
  fs::create_hard_link(from, to, e);
  if (e)
    fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

int runFinish(const BatchPlan& plan) {
  if (plan.mapDone()) {
    std::printf("finish: %s is the map of these drives: nothing to do\n", plan.mapDir().c_str());
    return 0;
  }
  const auto start = Clock::now();
  Figures merged_figures, mesh_figures;
  for (int k = 0; k < plan.options().merge_tasks; ++k) {
    for (const auto& [key, v] : readFigures(sharePath(plan, "merge", std::size_t(k)), "merge share " + std::to_string(k)))
      merged_figures[key] += v;
    for (const auto& [key, v] : readFigures(sharePath(plan, "mesh", std::size_t(k)), "mesh share " + std::to_string(k)))
      mesh_figures[key] += v;
  }
  const TsdfStore work = TsdfStore::open(plan.mergeDir());
  OutputFolder map(plan.mapDir(), "msf_batch");
  const fs::path stage = map.dir();
  fs::create_directories(stage / "tsdf");
  fs::create_directories(stage / "tiles");
  linkInto(fs::path(work.directory()) / "tsdf" / "index.txt", stage / "tsdf" / "index.txt");
  for (const GridIndex& t : work.tiles()) {
    linkInto(work.blockPath(t), stage / "tsdf" / (TsdfStore::tileName(t) + ".blk"));
    const fs::path mesh = fs::path(plan.mergeDir()) / "tiles" / (TsdfStore::tileName(t) + ".ply");
    if (fs::is_regular_file(mesh))
      linkInto(mesh, stage / "tiles" / mesh.filename());
  }
  const TsdfStore staged = TsdfStore::open(stage.string());
  const std::size_t triangles =
      StreamingMap::unionOfTiles(staged, staged.tiles(), (stage / "tiles").string(), (stage / "mesh.ply").string());
  if (triangles == 0)
    throw InvalidInputError("the merged map of " + std::to_string(plan.drives().size()) +
                            " drives has no surface: nothing is written to '" + plan.mapDir() + "'");
  std::ostringstream json;
  json << "{\n  \"drives\": [" << drivesJson(plan) << "\n  ],\n  \"voxel_size_m\": " << staged.voxelSize()
       << ",\n  \"tile_m\": " << staged.tileSizeM() << ",\n  \"max_weight\": " << plan.pipelineConfig().integrator.max_weight
       << ",\n  \"tiles\": " << merged_figures["tiles"] << ",\n  \"tiles_shared\": " << merged_figures["tiles_shared"]
       << ",\n  \"blocks\": " << merged_figures["blocks"] << ",\n  \"blocks_shared\": " << merged_figures["blocks_shared"]
       << ",\n  \"voxels_shared\": " << merged_figures["voxels_shared"] << ",\n  \"voxels_capped\": "
       << merged_figures["voxels_capped"] << ",\n  \"merge_tasks\": " << plan.options().merge_tasks
       << ",\n  \"merge_s\": " << merged_figures["ms"] / 1000.0 << ",\n  \"mesh_s\": " << mesh_figures["ms"] / 1000.0
       << ",\n  \"finish_s\": " << secondsSince(start) << ",\n  \"triangles\": " << triangles << "\n}\n";
  writeAtomically((stage / "summary.json").string(), [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << json.str();
    if (!out.flush())
      throw IOError("cannot write '" + tmp + "'");
  });
  map.commit();
  plan.markMapDone();
  std::error_code e;
  fs::remove_all(plan.mergeDir(), e);
  std::printf("finish: %s: %zu tiles, %zu triangles\n", plan.mapDir().c_str(), work.tiles().size(), triangles);
  return 0;
}

} // namespace

BatchTask BatchTask::parse(const std::string& text) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  BatchTask task;
  if (kind == "finish" && colon == std::string::npos) {
    task.kind = Kind::Finish;
    return task;
  }
  const std::string number = colon == std::string::npos ? "" : text.substr(colon + 1);
  if ((kind == "drive" || kind == "merge" || kind == "mesh") && !number.empty() &&
      number.find_first_not_of("0123456789") == std::string::npos && number.size() < 9) {
    task.kind = kind == "drive" ? Kind::Drive : kind == "merge" ? Kind::Merge : Kind::Mesh;
    task.index = std::stoul(number);
    return task;
  }
  throw InvalidInputError("task '" + text + "' is not drive:N, merge:N, mesh:N or finish");
}

std::string BatchTask::text() const {
  switch (kind) {
  case Kind::Drive:
    return "drive:" + std::to_string(index);
  case Kind::Merge:
    return "merge:" + std::to_string(index);
  case Kind::Mesh:
    return "mesh:" + std::to_string(index);
  case Kind::Finish:
    break;
  }
  return "finish";
}

std::vector<std::string> batchTaskCommand(const BatchPlan& plan, const BatchTask& task) {
  return {plan.options().batch, "-o", plan.out(), "-run", task.text()};
}

int runBatchTask(const BatchPlan& plan, const BatchTask& task) {
  const std::size_t shares = static_cast<std::size_t>(plan.options().merge_tasks);
  if ((task.kind == BatchTask::Kind::Drive && task.index >= plan.drives().size()) ||
      ((task.kind == BatchTask::Kind::Merge || task.kind == BatchTask::Kind::Mesh) && task.index >= shares))
    throw InvalidInputError("task '" + task.text() + "' is out of range: the plan has " +
                            std::to_string(plan.drives().size()) + " drives and " + std::to_string(shares) +
                            " merge shares");
  switch (task.kind) {
  case BatchTask::Kind::Drive:
    return runDrive(plan, task.index);
  case BatchTask::Kind::Merge:
    return runMerge(plan, task.index);
  case BatchTask::Kind::Mesh:
    return runMesh(plan, task.index);
  case BatchTask::Kind::Finish:
    break;
  }
  return runFinish(plan);
}

} // namespace msf
