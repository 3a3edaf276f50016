// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// Parameters of the per-pixel confidence of an SGBM disparity image: the `confidence_` keys of
/// section `stereo`. Wrong matches cluster near the holes of the disparity image (speckle-
/// filtered or rejected pixels: matching failed nearby, or an occlusion edge) and where the
/// disparity varies within a few pixels (a depth edge or a mismatch); image texture, the usual
/// cue, predicts little on KITTI.
struct StereoConfidenceConfig {
  static constexpr const char* kSection = "stereo";
  float hole_distance_px = 15.f;
  int range_window_px = 5;
  float range_free_px = 1.f;
  float range_scale_px = 1.f;

  template <class Keys>
  void keys(Keys& k) {
    k("confidence_hole_distance_px", hole_distance_px, above(0),
      "confidence 1 - exp(-distance to the nearest hole / this), px");
    k("confidence_range_window_px", range_window_px, atLeast(1),
      "window of the local disparity range (max - min of the disparities), px (odd)");
    k("confidence_range_free_px", range_free_px, atLeast(0), "a local range up to this costs no confidence, px");
    k("confidence_range_scale_px", range_scale_px, above(0),
      "beyond it, confidence falls as exp(-excess / this), px");
  }
  /// Throws ConfigError naming the key of a value out of range.
  void validate() const;
};

/// Confidence in [0, 1] of each pixel of `disparity` (CV_32F, <= 0 or NaN = none; 0 there):
/// (1 - exp(-d_hole / hole_distance_px)) * exp(-max(0, range - range_free_px) / range_scale_px),
/// with d_hole the L1 distance in pixels to the nearest pixel without disparity and range the
/// max - min of the valid disparities in the window. Throws InvalidInputError for a wrong type.
cv::Mat stereoConfidence(const cv::Mat& disparity, const StereoConfidenceConfig& config = {});

} // namespace msf
