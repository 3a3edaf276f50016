// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/reconstruction/depth_frame.h>

#include <pcl/point_cloud.h>

namespace msf {

/// A fused depth frame as msf_fuse writes it: an organized cloud of camera 0 with the frame's
/// colour and per-pixel weight (NaN where there is no depth).
pcl::PointCloud<PointXYZRGBWeight> fusedCloud(const DepthFrame& fused, const Calibration& calibration);

} // namespace msf
