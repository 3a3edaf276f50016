// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace msf {

/// A LiDAR scan as a file holds it: the points in the sensor's order, and per point its ring
/// and time when the file has them.
struct ScanFile {
  pcl::PointCloud<pcl::PointXYZI> points;
  std::vector<std::uint16_t> ring;  ///< a field `ring`; empty when absent
  std::vector<float> time_s;        ///< a field `time` or `t` (seconds from the sweep's start); empty when absent
};

/// Reads a scan by its extension: a KITTI .bin (float32 x, y, z, reflectance), or a .pcd or
/// .ply with fields x y z of any numeric type and, optionally, intensity (or reflectivity),
/// ring and time (or t, in seconds; nanoseconds when an integer field). Points with a
/// non-finite coordinate are dropped (with their ring and time). Throws IOError naming the
/// file when it is missing, malformed, lacks x, y or z, or has no finite point.
ScanFile loadScanFile(const std::string& path);

} // namespace msf
