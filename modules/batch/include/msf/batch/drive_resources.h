// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/drive_list.h>
#include <msf/pipeline/reconstructor.h>

#include <cstddef>
#include <string>

namespace msf {

/// What a drive's task needs, known before it runs: its frames and the peak memory that
/// msf_reconstruct predicts for it (Reconstructor::predictMemory, the same model and poses the run
/// prints as "Memory: predicted peak N MiB"), and what the task asks the scheduler for.
struct DriveResources {
  std::size_t frames = 0;
  double predicted_mb = 0;  ///< the run's predicted peak
  std::size_t request_mb = 0; ///< the prediction with a margin, rounded up to kRequestStepMb
  /// Requests are rounded up to steps of this (so that drives of about one size share a job array).
  static constexpr std::size_t kRequestStepMb = 256;
  /// A margin over the prediction (which holds the measured peaks of the runs in
  /// docs/results.md, "Memory: predicted and measured peaks"), for drives unlike them.
  static constexpr double kMargin = 1.2;
};

/// The resources of `drive` reconstructed with `config` (its streaming settings included) over
/// the frames of `frames` ("a:b"), by a process of `process_mb` before its run (the caller's
/// resident memory before it predicted any drive: what a new msf_reconstruct starts from).
/// Throws InvalidInputError naming the drive when its poses are not known before the run (a
/// batch merges drives whose poses share a world: give a poses file), ConfigError when the
/// streaming radius is below what the run needs (as the run would at its start), IOError /
/// ConfigError as Sequence and Reconstructor do.
DriveResources predictDriveResources(const Drive& drive, const PipelineConfig& config, const std::string& frames,
                                     double process_mb);

} // namespace msf
