// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

namespace msf {

/// The beams' elevations a scan shows through its per-point rings (a ROS driver's `ring` field):
/// each ring's median elevation in the LiDAR's frame (z up), in degrees, lowest first, over the
/// rings with at least `min_points` returns. Empty when `rings` is empty or names fewer than
/// two such rings: a rig that lists no beams then keeps KITTI's sizes.
std::vector<double> beamElevationsFromRings(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                            const std::vector<std::uint16_t>& rings, std::size_t min_points = 20);

} // namespace msf
