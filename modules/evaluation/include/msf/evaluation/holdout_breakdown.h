// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>

#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

namespace msf {

/// Ground-truth pixels of protocol 2 that camera 0 cannot see: a held-out return with an
/// input return within `radius_px` pixels (Chebyshev) whose disparity is larger by more than
/// the D1 threshold. The input return lies on (or next to) the camera's ray towards the
/// held-out one and in front of it, so the camera sees the nearer surface there; the
/// held-out return comes from a LiDAR beam that passed beside it (leaves, a fence, an
/// object's silhouette). No camera-based estimate can be right at such a pixel.
/// gt_depth, input_depth: CV_32FC1 metres (not > 0 = none), one size. Returns CV_8UC1
/// (255 = hidden). Throws InvalidInputError naming the image whose type or size is wrong.
cv::Mat hiddenGroundTruthMask(const cv::Mat& gt_depth, const cv::Mat& input_depth, double focal_baseline,
                              int radius_px = 1, const D1Threshold& d1 = {});

/// A named subset of the ground-truth pixels of a frame.
struct HoldoutRegion {
  std::string name;
  cv::Mat mask; ///< CV_8UC1, non-zero = in the region
};

/// The regions msf_holdout -breakdown reports, so that one sees which pixels carry the
/// errors: "visible" and "hidden" (hiddenGroundTruthMask, radius 1) split the ground truth;
/// so do the depth bands "z < 20 m", "z 20-40 m", "z >= 40 m" of the ground truth, where one
/// pixel of disparity error is up to 1 m, 4 m and more.
std::vector<HoldoutRegion> holdoutRegions(const cv::Mat& gt_depth, const cv::Mat& input_depth,
                                          double focal_baseline, const D1Threshold& d1 = {});

/// The metrics of one region, pooled over frames.
struct RegionMetrics {
  std::string region;
  DepthMetrics metrics;
};

} // namespace msf
