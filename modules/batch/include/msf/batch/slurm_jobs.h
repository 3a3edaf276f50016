// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/batch_plan.h>
#include <msf/batch/batch_tasks.h>

#include <string>
#include <vector>

namespace msf {

/// Where and how long the jobs may run (sbatch's --partition, --time).
struct SlurmOptions {
  std::string partition;  ///< "": the cluster's default
  int time_min = 0;       ///< per task; 0: the partition's limit
};

/// The ids of a batch's jobs, in the order they depend on each other.
struct SlurmSubmission {
  std::vector<std::string> drive_jobs;  ///< one job array per memory request
  std::string merge_job, mesh_job, finish_job;
  std::vector<std::string> all() const;
};

/// Memory (MiB) of the merge and mesh shares and of the finish: a share holds one tile of the
/// merged store at a time (at most tile_blocks^3 blocks of 6 KiB, and the sums of the shared
/// ones) and the tiles around it; the finish, the positions of the vertices on tile borders.
constexpr int kMergeTaskMemoryMb = 512;
constexpr int kFinishTaskMemoryMb = 1024;

/// The script of one stage of the batch: a job array over `indices` of `kind` tasks (a single
/// job for the finish) that runs `msf_batch -o OUT -run KIND:$SLURM_ARRAY_TASK_ID`, asks for
/// `memory_mb` and `cpus`, is requeued when preempted or its node fails (--requeue), and
/// requeues itself when the task fails, until the plan's max_attempts (each attempt starts the
/// task from nothing); its output is appended to `OUT/logs/slurm_<kind>_<index>.out`.
std::string slurmStageScript(const BatchPlan& plan, BatchTask::Kind kind, const std::vector<std::size_t>& indices,
                             std::size_t memory_mb, int cpus, const SlurmOptions& options);

/// Submits what is not done yet (sbatch --parsable): an array of the drives not done per memory
/// request (DriveResources::request_mb), then the merge shares (afterok on the drive arrays),
/// the mesh shares (afterok on the merges) and the finish (afterok on the meshes); dependents
/// are cancelled when what they wait for fails (--kill-on-invalid-dep). The scripts stay in
/// OUT/jobs/ and the ids in OUT/jobs/submitted.txt. Nothing is submitted when the map is done.
/// Throws IOError quoting sbatch's error.
SlurmSubmission submitToSlurm(const BatchPlan& plan, const SlurmOptions& options);

/// Waits until none of `jobs` is pending or running (squeue), polling every `poll_s`; at most
/// `timeout_s` (0: no bound). Returns false when the bound ran out. Throws IOError when squeue
/// keeps failing.
bool waitForSlurm(const SlurmSubmission& jobs, double timeout_s, double poll_s = 2.0);

} // namespace msf
