// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/holdout_breakdown.h>
#include <msf/io/organized_conversion.h>

#include "image_checks.h"

#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <limits>
#include <string>

namespace msf {

namespace {
inline bool has(float z) { return z > 0.f && z < std::numeric_limits<float>::infinity(); }
} // namespace

cv::Mat hiddenGroundTruthMask(const cv::Mat& gt_depth, const cv::Mat& input_depth, double focal_baseline,
                              int radius_px, const D1Threshold& d1) {
  if (gt_depth.empty())
    throw InvalidInputError("hold-out breakdown: the ground-truth depth is empty");
  detail::requireLikeGroundTruth(gt_depth, "hold-out breakdown", "the ground-truth depth", gt_depth.size());
  detail::requireLikeGroundTruth(input_depth, "hold-out breakdown", "the input depth", gt_depth.size());
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("hold-out breakdown: focal length x baseline must be > 0, not " +
                            std::to_string(focal_baseline));
  if (radius_px < 0)
    throw InvalidInputError("hold-out breakdown: the radius must be >= 0, not " + std::to_string(radius_px));
  // The largest input disparity around each pixel (0 where there is none).
  cv::Mat nearest = depthToDisparity(input_depth, focal_baseline);
  cv::dilate(nearest, nearest,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius_px + 1, 2 * radius_px + 1)));
  cv::Mat hidden(gt_depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < gt_depth.rows; ++v) {
    const float* g = gt_depth.ptr<float>(v);
    const float* d = nearest.ptr<float>(v);
    std::uint8_t* out = hidden.ptr<std::uint8_t>(v);
    for (int u = 0; u < gt_depth.cols; ++u) {
      if (!has(g[u]))
        continue;
      const double d_gt = focal_baseline / g[u], excess = d[u] - d_gt;
      if (d1.exceeded(excess, d_gt))
        out[u] = 255;
    }
  }
  return hidden;
}

std::vector<HoldoutRegion> holdoutRegions(const cv::Mat& gt_depth, const cv::Mat& input_depth,
                                          double focal_baseline, const D1Threshold& d1) {
  const cv::Mat hidden = hiddenGroundTruthMask(gt_depth, input_depth, focal_baseline, 1, d1);
  std::vector<HoldoutRegion> regions{{"visible", cv::Mat()}, {"hidden", hidden},
                                     {"z < 20 m", cv::Mat()}, {"z 20-40 m", cv::Mat()}, {"z >= 40 m", cv::Mat()}};
  cv::Mat has_gt = gt_depth > 0.f;
  regions[0].mask = has_gt & ~hidden;
  regions[2].mask = has_gt & (gt_depth < 20.f);
  regions[3].mask = (gt_depth >= 20.f) & (gt_depth < 40.f);
  regions[4].mask = (gt_depth >= 40.f) & (gt_depth < std::numeric_limits<float>::infinity());
  return regions;
}

} // namespace msf
