// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace msf {

/// The beams' elevations a scan shows through its per-point rings (a ROS driver's `ring` field):
/// each ring's median elevation in the LiDAR's frame (z up), in degrees, lowest first, over the
/// rings with at least `min_points` returns (a top beam that sees only sky drops out). Empty when
/// `rings` is empty, names fewer than two such rings, such rings are not numbered one after the
/// other (a beam missing between two), or a ring's returns spread over more than a degree (not a
/// beam's: a field named ring that numbers something else); a rig that lists no beams then keeps
/// KITTI's sizes.
std::vector<double> beamElevationsFromRings(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                            const std::vector<std::uint16_t>& rings, std::size_t min_points = 20);

/// What a source says of beams it took from a scan: "16 beams from the first scan's rings, -15.0
/// to 15.0 degrees (a rig file's lidar.beam_elevations_deg sets them)".
std::string beamsFromRingsNote(const std::vector<double>& beams);

} // namespace msf
