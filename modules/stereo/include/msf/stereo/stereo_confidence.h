// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>
#include <opencv2/core/persistence.hpp>

namespace msf {

/// Parameters of the per-pixel confidence of an SGBM disparity image.
/// On KITTI (odometry 04, LiDAR as ground truth) the share of disparities off by more than
/// 3 px is 25 % within 7 px of a hole of the disparity image (speckle-filtered or rejected
/// pixels: matching failed nearby, or an occlusion edge), under 0.5 % beyond 30 px; and it is
/// 14 % where the disparity varies by more than 2 px within 5x5 pixels (a depth edge or a
/// mismatch), 1-3 % elsewhere. Image texture, the usual cue, predicts little there.
struct StereoConfidenceConfig {
  float hole_distance_px = 15.f; ///< confidence 1 - exp(-distance to the nearest hole / this)
  int range_window_px = 5;       ///< odd window of the local disparity range
  float range_free_px = 1.f;     ///< a local range up to this costs nothing
  float range_scale_px = 1.f;    ///< beyond it, confidence falls as exp(-excess / this)

  /// Throws ConfigError naming the key of a value out of range.
  void validate() const;
};

/// Confidence in [0, 1] of each pixel of `disparity` (CV_32F, <= 0 or NaN = none; 0 there):
/// (1 - exp(-d_hole / hole_distance_px)) * exp(-max(0, range - range_free_px) / range_scale_px),
/// with d_hole the L1 distance in pixels to the nearest pixel without disparity and range the
/// max - min of the valid disparities in the window. Throws InvalidInputError for a wrong type.
cv::Mat stereoConfidence(const cv::Mat& disparity, const StereoConfidenceConfig& config = {});

} // namespace msf
