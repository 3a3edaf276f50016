// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/fusion_bounds.h>

#include <algorithm>
#include <cmath>

namespace msf {

std::string fusionBoundName(FusionBound bound) {
  return bound == FusionBound::Select ? "bound_select" : "bound_blend";
}

cv::Mat fusionBoundDepth(const cv::Mat& ground_truth, const cv::Mat& first, const cv::Mat& second,
                         FusionBound bound) {
  for (const cv::Mat* image : {&first, &second})
    if (image->type() != CV_32FC1 || image->size() != ground_truth.size() || ground_truth.type() != CV_32FC1)
      throw InvalidInputError("fusion bound: the ground truth and both inputs must be CV_32FC1 images of one size, got " +
                              std::to_string(ground_truth.cols) + "x" + std::to_string(ground_truth.rows) + ", " +
                              std::to_string(first.cols) + "x" + std::to_string(first.rows) + " and " +
                              std::to_string(second.cols) + "x" + std::to_string(second.rows));
  cv::Mat out(ground_truth.size(), CV_32FC1);
  for (int v = 0; v < out.rows; ++v) {
    const float* gt = ground_truth.ptr<float>(v);
    const float* a = first.ptr<float>(v);
    const float* b = second.ptr<float>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < out.cols; ++u) {
      const bool has_a = a[u] > 0.f, has_b = b[u] > 0.f;
      if (!(gt[u] > 0.f) || !has_b) {
        o[u] = has_a ? a[u] : (has_b ? b[u] : 0.f);
      } else if (!has_a) {
        o[u] = b[u];
      } else if (bound == FusionBound::Select) {
        o[u] = std::abs(a[u] - gt[u]) <= std::abs(b[u] - gt[u]) ? a[u] : b[u];
      } else {
        o[u] = std::clamp(gt[u], std::min(a[u], b[u]), std::max(a[u], b[u]));
      }
    }
  }
  return out;
}

} // namespace msf
