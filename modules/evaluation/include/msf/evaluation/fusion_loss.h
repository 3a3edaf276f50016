// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>

#include <opencv2/core/mat.hpp>

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace msf {

/// Where a per-pixel fusion of two depth images is bad (D1) although one of its inputs is
/// right: the pixels a better choice could still win (FusionBound::Select is bad only where
/// both inputs are), counted by which input was right and what the fusion gave there
/// (msf_holdout -bounds). Beside the losses, the pixels where the fusion gave an input that was
/// right over the other's wrong depth: against TheOtherInput's losses (an input given over the
/// other's right depth), they say how often taking one input over the other was right.
struct FusionLoss {
  /// What the fusion gave at a pixel it lost.
  enum Gave {
    TheOtherInput, ///< within 1 % of the wrong input's depth
    Between,       ///< a value strictly between the two inputs, not near either
    Nothing,       ///< no depth
    Elsewhere,     ///< any other value (a step after the per-pixel fusion moved it)
    kGaveCount
  };
  std::size_t ground_truth = 0;                   ///< pixels with ground truth, in all
  std::array<std::size_t, kGaveCount> first_right{};  ///< lost where only the first input is right
  std::array<std::size_t, kGaveCount> second_right{}; ///< lost where only the second input is right
  std::size_t both_right = 0;                     ///< lost where both inputs are right
  std::size_t gave_first_right = 0;  ///< the fusion gave the first input, right, over the second's wrong depth
  std::size_t gave_second_right = 0; ///< the fusion gave the second input, right, over the first's wrong depth

  /// Counts one frame: the ground truth, the two inputs and the fusion, CV_32FC1 depth images
  /// of one size (0 = none); `focal_baseline` f B turns depth into disparity. Throws
  /// InvalidInputError on sizes or types.
  void add(const cv::Mat& ground_truth_depth, const cv::Mat& first, const cv::Mat& second, const cv::Mat& fused,
           double focal_baseline, const D1Threshold& d1);
  /// The pixels lost, in all.
  std::size_t lost() const;
};

/// "What was lost to bound_select" table: a row per fusion (name, counts), the shares of the
/// ground truth where it is bad and the named input right, by what it gave there; then, where
/// both inputs have a depth and one is right, how often giving each input was right and wrong.
std::string formatFusionLoss(const std::vector<std::pair<std::string, FusionLoss>>& rows, const std::string& first,
                             const std::string& second);

} // namespace msf
