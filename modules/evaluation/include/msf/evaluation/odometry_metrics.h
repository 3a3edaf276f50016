// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>

#include <cstddef>
#include <vector>

namespace msf {

/// Evaluation protocol 5 (odometry) of an estimated trajectory against a reference, both
/// T_world_cam0 with a pose per frame.
struct OdometryMetrics {
  std::size_t poses = 0;
  double path_length_m = 0;  ///< of the reference

  /// KITTI devkit (evaluate_odometry.cpp): for each first frame and segment length, the
  /// relative pose error between the first frame and the first one farther along the
  /// reference's path than the length, over that length; means over all segments. The
  /// devkit's lengths are 100, 200, ..., 800 m from every 10th frame; a reference shorter
  /// than 100 m has none of them, and then the lengths are k L / 8 (k = 1..7, L its path
  /// length) from every frame (`devkit_lengths` false).
  std::vector<double> segment_lengths_m;
  bool devkit_lengths = true;
  std::size_t segments = 0;
  double translation_error_pct = 0;     ///< mean translation error over segment length, %
  double rotation_error_deg_per_m = 0;  ///< mean rotation error over segment length

  /// Absolute trajectory error after aligning the first poses (the estimate moved by
  /// T_ref[0] * T_est[0]^-1, as KITTI's poses all start at the identity): positions only.
  double ate_rmse_m = 0, ate_mean_m = 0, ate_max_m = 0;

  /// The last pose after the same alignment: position error, and in % of the path length.
  double end_drift_m = 0, end_drift_pct = 0;
  double end_rotation_error_deg = 0;
};

/// Throws InvalidInputError when the lists differ in size, hold fewer than 2 poses, or the
/// reference does not move.
OdometryMetrics evaluateOdometry(const PoseList& estimate, const PoseList& reference);

/// The estimate moved so that its first pose is the reference's (what the metrics compare).
PoseList alignFirstPose(const PoseList& estimate, const PoseList& reference);

} // namespace msf
