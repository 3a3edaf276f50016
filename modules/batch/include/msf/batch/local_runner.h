// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/batch_plan.h>
#include <msf/batch/batch_tasks.h>

#include <vector>

namespace msf {

/// The batch on this machine without a scheduler: the same task commands as the Slurm jobs
/// (batchTaskCommand), `parallel` at a time, the drives first (no more at once than their
/// predicted memory fits in `memory_mb`), then the merge shares, the mesh shares and the
/// finish. A task that fails runs again from nothing, up to the plan's max_attempts, as a
/// requeued job would. Each task's own output goes to `OUT/logs/task_<kind>_<n>.log`.
class LocalRunner {
public:
  /// Throws InvalidInputError when `parallel` < 1.
  LocalRunner(const BatchPlan& plan, int parallel, double memory_mb);
  /// Runs what is not done yet. Returns true when the map is done; false (having said which
  /// task failed after its last attempt, and where its log is) otherwise.
  bool run();

private:
  /// Runs `tasks` `parallel_` at a time (drives also within memory_mb_). False when one failed
  /// on its last attempt.
  bool runStage(const std::vector<BatchTask>& tasks);

  const BatchPlan& plan_;
  int parallel_;
  double memory_mb_;
};

} // namespace msf
