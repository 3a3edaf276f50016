// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// Work images of supportAtDepthEdges, kept between frames.
struct EdgeSupportBuffers {
  cv::Mat returns;           ///< CV_16UC1, real returns' disparities in 1/8 px, 0 where none
  cv::Mat largest, smallest; ///< CV_16UC1, their extremes over the window
  cv::Mat zeros;             ///< one row of distances 0, when the caller gives no distance image
};

/// The last step of both fusion methods (fusion.edge_support): where the real LiDAR returns
/// in the window around a pixel span a depth edge (their disparities differ by more than
/// edge_jump_px), a fused disparity between the window's nearest and farthest returns and
/// farther than edge_tolerance_px from both lies between the two surfaces (the interpolation's hole filling blends them, stereo
/// fattens the nearer one) and takes the depth of the return nearest it in disparity.
///
/// lidar_depth: CV_32FC1 metres (not > 0 = none); lidar_distance: CV_32FC1 pixels to the
/// nearest real return, 0 on one (empty: every LiDAR depth is one); fused_depth: CV_32FC1
/// metres, changed in place. The caller checks the sizes and types.
void supportAtDepthEdges(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, float focal_baseline,
                         const DepthFusionConfig& config, cv::Mat& fused_depth, EdgeSupportBuffers& buffers);

} // namespace msf
