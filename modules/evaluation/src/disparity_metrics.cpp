// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/message_text.h>
#include <msf/evaluation/disparity_metrics.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

namespace {
inline bool has(float d) { return d > 0.f && std::isfinite(d); }
} // namespace

DisparityRegionErrors& DisparityRegionErrors::operator+=(const DisparityRegionErrors& other) {
  gt_pixels += other.gt_pixels;
  estimated += other.estimated;
  bad += other.bad;
  bad_estimated += other.bad_estimated;
  evaluated += other.evaluated;
  abs_error_sum += other.abs_error_sum;
  return *this;
}

DisparityEvaluation& DisparityEvaluation::operator+=(const DisparityEvaluation& other) {
  background += other.background;
  foreground += other.foreground;
  all += other.all;
  has_object_map = has_object_map || other.has_object_map;
  return *this;
}

cv::Mat interpolateBackground(const cv::Mat& disparity) {
  if (disparity.type() != CV_32FC1)
    throw InvalidInputError("disparity image must be CV_32FC1 to interpolate, got another type");
  cv::Mat out(disparity.size(), CV_32FC1);
  const int rows = out.rows, cols = out.cols;
  for (int v = 0; v < rows; ++v) {
    const float* in = disparity.ptr<float>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < cols; ++u)
      o[u] = has(in[u]) ? in[u] : 0.f;
  }
  std::vector<unsigned char> row_valid(static_cast<std::size_t>(rows), 0);
  for (int v = 0; v < rows; ++v) {
    float* o = out.ptr<float>(v);
    int first = -1, last = -1;
    for (int u = 0; u < cols; ++u) {
      if (o[u] <= 0.f)
        continue;
      // An interior gap takes the smaller disparity of its two ends: occlusions and holes
      // are usually background.
      if (last >= 0 && u - last > 1) {
        const float fill = std::min(o[last], o[u]);
        std::fill(o + last + 1, o + u, fill);
      }
      if (first < 0)
        first = u;
      last = u;
    }
    if (first < 0)
      continue;
    std::fill(o, o + first, o[first]);
    std::fill(o + last + 1, o + cols, o[last]);
    row_valid[static_cast<std::size_t>(v)] = 1;
  }
  // Empty rows: the nearest filled row, upwards first for the top, downwards for the bottom
  // (the devkit's column extrapolation, which after the row pass only reaches empty rows).
  int first_row = -1, last_row = -1;
  for (int v = 0; v < rows; ++v)
    if (row_valid[static_cast<std::size_t>(v)]) {
      if (first_row < 0)
        first_row = v;
      last_row = v;
    }
  if (first_row < 0)
    return out;
  for (int v = 0; v < first_row; ++v)
    out.row(first_row).copyTo(out.row(v));
  for (int v = last_row + 1; v < rows; ++v)
    out.row(last_row).copyTo(out.row(v));
  return out;
}

DisparityEvaluation evaluateDisparity(const cv::Mat& ground_truth, const cv::Mat& estimate, const cv::Mat& object_map,
                                      const DisparityEvalOptions& options) {
  if (ground_truth.type() != CV_32FC1)
    throw InvalidInputError("ground-truth disparity must be CV_32FC1");
  if (estimate.type() != CV_32FC1)
    throw InvalidInputError("estimated disparity must be CV_32FC1");
  if (estimate.size() != ground_truth.size())
    throw InvalidInputError("estimated disparity is " + sizeText(estimate) + " but the ground truth is " +
                            sizeText(ground_truth));
  cv::Mat objects;
  if (!object_map.empty()) {
    if (object_map.channels() != 1 || (object_map.depth() != CV_8U && object_map.depth() != CV_16U &&
                                       object_map.depth() != CV_32S))
      throw InvalidInputError("object map must be a single-channel 8- or 16-bit image");
    if (object_map.size() != ground_truth.size())
      throw InvalidInputError("object map is " + sizeText(object_map) + " but the ground truth is " +
                              sizeText(ground_truth));
    objects = object_map != 0; // CV_8U, 255 = foreground
  }
  const cv::Mat filled = options.interpolate_background ? interpolateBackground(estimate) : estimate;

  DisparityEvaluation result;
  result.has_object_map = !objects.empty();
  for (int v = 0; v < ground_truth.rows; ++v) {
    const float* gt = ground_truth.ptr<float>(v);
    const float* est = estimate.ptr<float>(v);
    const float* fill = filled.ptr<float>(v);
    const unsigned char* obj = objects.empty() ? nullptr : objects.ptr<unsigned char>(v);
    for (int u = 0; u < ground_truth.cols; ++u) {
      if (!has(gt[u]))
        continue;
      DisparityRegionErrors& region = (obj && obj[u]) ? result.foreground : result.background;
      const bool estimated = has(est[u]);
      const bool evaluated = has(fill[u]);
      const float err = evaluated ? std::fabs(fill[u] - gt[u]) : 0.f;
      const bool bad = !evaluated || (err > options.abs_threshold_px && err > options.rel_threshold * gt[u]);
      for (DisparityRegionErrors* r : {&region, &result.all}) {
        ++r->gt_pixels;
        r->bad += bad;
        if (estimated) {
          ++r->estimated;
          r->bad_estimated += bad;
        }
        if (evaluated) {
          ++r->evaluated;
          r->abs_error_sum += err;
        }
      }
    }
  }
  return result;
}

} // namespace msf
