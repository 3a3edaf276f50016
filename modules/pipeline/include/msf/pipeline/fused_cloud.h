// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/pipeline/reconstructor.h>

#include <pcl/point_cloud.h>

namespace msf {

/// A frame's fused depth as msf_fuse writes it: an organized cloud of camera 0 (NaN where there
/// is no depth) with the fused colour, weight and free-space weight, and the open sky where the
/// frame found it (FrameResult::sky, with sky carving).
pcl::PointCloud<PointXYZRGBWeight> fusedCloud(const FrameResult& result, const Calibration& calibration);

} // namespace msf
