// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <string>

namespace msf {

/// What the ground truth allows a per-pixel fusion of two depth images to reach: the rows a
/// fusion method is measured against, beside its inputs (msf_holdout -bounds).
enum class FusionBound {
  /// Per pixel, the input nearer the truth in depth: the least depth MAE of any method
  /// that picks one of its two inputs at each pixel.
  Select,
  /// Per pixel, the value between the two inputs nearest the truth (the truth itself where
  /// it lies between them): the least error, in depth and in disparity, of any method whose
  /// output is a weighted mean of its inputs, as eq. 6 and inverse-variance fusion are.
  Blend
};

/// Row name of a bound: "bound_select" or "bound_blend".
std::string fusionBoundName(FusionBound bound);

/// The bound's depth image (CV_32FC1, 0 = none) from two inputs and the ground truth, all
/// CV_32FC1 of one size (0 = no value). Where only one input has a value it is taken; where
/// the truth is missing, the first input's. Throws InvalidInputError on sizes or types.
cv::Mat fusionBoundDepth(const cv::Mat& ground_truth, const cv::Mat& first, const cv::Mat& second,
                         FusionBound bound);

} // namespace msf
