// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/pipeline/depth_panel.h>
#include <msf/pipeline/reconstructor.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// The depth images of one frame of a run, top to bottom: the left image, the projected LiDAR
/// (`input_rings_only`: the input rings of the ring hold-out), the interpolated LiDAR, SGBM,
/// the fused depth and, with `true_depth`, the fused depth's error (report.md's panels).
cv::Mat framePanel(const FrameResult& result, bool input_rings_only, const cv::Mat& true_depth = cv::Mat());

} // namespace msf
