// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/drive_list.h>
#include <msf/pipeline/pipeline_config.h>

#include <cstddef>
#include <string>
#include <vector>

namespace msf {

/// How a batch runs: the options of msf_batch that every task must see alike.
struct BatchOptions {
  std::string batch;        ///< msf_batch itself: the command of every task
  std::string reconstruct;  ///< msf_reconstruct, which a drive's task runs
  std::string config;       ///< -config FILE ("": the defaults)
  std::string frames = "0:";
  double stream_m = 101.0;  ///< streaming.active_radius_m of every drive: its TSDF is a store on disk
  double voxel_m = 0.0;     ///< tsdf_volume.voxel_size_m (0: the config's)
  int cpus = 2;             ///< per drive task
  int merge_tasks = 4;      ///< tasks that merge (and then mesh) shares of the tiles side by side
  int max_attempts = 3;     ///< a task that fails runs again from nothing until this many attempts
};

/// A batch in its output root OUT, written to OUT/plan.txt before anything runs and read by
/// every task, so that the tasks of one submission agree on what they do:
///   OUT/plan.txt             the options and the drives (name, dataset, poses, predicted memory)
///   OUT/drives/NAME/         msf_reconstruct's output for the drive (an OutputFolder: committed whole)
///   OUT/state/drive_NAME.done  the request it was made for (dataset, frames, poses, options and
///                            the digests of the config and poses files): a drive is done when
///                            its folder is committed and this matches the plan's request;
///                            OUT/state/map.done likewise for the map
///   OUT/logs/                each drive's log (its attempts, appended) and the tasks' logs
///   OUT/merge/               the merge's work: merged tiles (tsdf/) and their meshes (tiles/)
///   OUT/map/                 the merged map (an OutputFolder): tsdf/, tiles/, mesh.ply, summary.json
///   OUT/jobs/                the Slurm job scripts and the ids they were submitted as
class BatchPlan {
public:
  /// A plan for `drives` (named: nameDrives) in `out`, its config read and checked.
  BatchPlan(std::string out, std::vector<Drive> drives, BatchOptions options);
  /// The plan in OUT/plan.txt. Throws IOError naming the file when it is missing or garbled.
  static BatchPlan load(const std::string& out);
  /// Throws IOError naming an entry of OUT that is not a batch's: OUT must be absent, empty or
  /// an earlier batch's (its plan.txt and only the entries a batch writes).
  void requireRoot() const;
  /// Makes OUT (requireRoot first) and writes OUT/plan.txt atomically.
  void save() const;

  const std::string& out() const { return out_; }
  const std::vector<Drive>& drives() const { return drives_; }
  const BatchOptions& options() const { return options_; }
  /// The configuration every drive runs with: the config file, -voxel and -stream applied.
  const PipelineConfig& pipelineConfig() const { return config_; }

  /// The drive's predicted peak (MiB) and the memory its task asks for, as set at planning.
  double predictedMb(std::size_t drive) const { return predicted_mb_.at(drive); }
  std::size_t requestMb(std::size_t drive) const { return request_mb_.at(drive); }
  void setResources(std::size_t drive, double predicted_mb, std::size_t request_mb);

  std::string driveDir(std::size_t drive) const;
  std::string driveLog(std::size_t drive) const;
  /// The msf_reconstruct command line of the drive's task.
  std::vector<std::string> reconstructCommand(std::size_t drive) const;
  /// What the drive is made for, as text (compared with OUT/state/NAME.done).
  std::string request(std::size_t drive) const;
  /// Committed (its manifest and summary.json) and made for this request.
  bool driveDone(std::size_t drive) const;
  void markDriveDone(std::size_t drive) const;
  /// Forgets that a drive was done (before its folder is made again).
  void clearDriveDone(std::size_t drive) const;

  std::string mergeDir() const;
  std::string mapDir() const;
  std::string logDir() const;
  std::string jobDir() const;
  /// What the map is made of: every drive's request and the merge's settings.
  std::string mapRequest() const;
  bool mapDone() const;
  void markMapDone() const;
  void clearMapDone() const;

  /// Marks OUT as a batch's root (OUT/plan.txt is what marks it).
  static const char* planName();

private:
  std::string statePath(const std::string& name) const;
  bool stampMatches(const std::string& name, const std::string& request) const;
  void writeStamp(const std::string& name, const std::string& request) const;

  std::string out_;
  std::vector<Drive> drives_;
  BatchOptions options_;
  PipelineConfig config_;
  std::string config_digest_;
  std::vector<std::string> poses_digests_;
  std::vector<double> predicted_mb_;
  std::vector<std::size_t> request_mb_;
};

/// FNV-1a (64 bit) of a file's bytes in hex: what a request records of a config or poses file.
/// Throws IOError naming the file when it cannot be read.
std::string fileDigest(const std::string& path);

} // namespace msf
