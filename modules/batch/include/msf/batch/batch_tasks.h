// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/batch_plan.h>

#include <cstddef>
#include <string>

namespace msf {

/// The units of work of a batch, each idempotent: run again after it finished, it does
/// nothing; run again after it failed or was killed, it starts from nothing. A scheduler (a
/// Slurm job array, or the local runner) runs each as `msf_batch -o OUT -run TASK`
/// (batchTaskCommand), in this order: every drive, then every merge share, then every mesh
/// share, then the finish.
struct BatchTask {
  enum class Kind { Drive, Merge, Mesh, Finish };
  Kind kind = Kind::Drive;
  std::size_t index = 0;  ///< the drive, or the share of the tiles (0 .. merge_tasks - 1)

  /// "drive:3", "merge:0", "mesh:1", "finish". Throws InvalidInputError naming the text.
  static BatchTask parse(const std::string& text);
  std::string text() const;
};

/// The command line that runs `task` of the batch in `plan.out()`.
std::vector<std::string> batchTaskCommand(const BatchPlan& plan, const BatchTask& task);

/// Runs `task`. A drive: msf_reconstruct with the drive's log (appended, one header per attempt),
/// then its done stamp once its folder is committed; nothing when it is done. A merge share:
/// the drives' stores' tiles of its share merged into OUT/merge/tsdf. A mesh share: those tiles
/// meshed into OUT/merge/tiles (the index first, which needs every merge share's tiles). The
/// finish: OUT/map committed (the merged store and tile meshes, their union mesh.ply and
/// summary.json), and OUT/merge removed. Returns the exit code (a drive's msf_reconstruct's on
/// failure); throws what the library throws, e.g. InvalidInputError naming the drives that are
/// not done when a merge share starts.
int runBatchTask(const BatchPlan& plan, const BatchTask& task);

} // namespace msf
