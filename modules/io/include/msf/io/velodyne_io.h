// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <string>

namespace msf {

struct VelodyneReadStats {
  std::size_t records = 0;           ///< records in the file (size / 16)
  std::size_t dropped_nonfinite = 0; ///< records with a NaN or infinite value, not kept
};

/// Reads a KITTI Velodyne .bin (float32 x, y, z, reflectance per record) into an
/// unorganized cloud in file order (file order carries the ring structure, see ring_split).
/// Throws IOError naming the file when it is missing or unreadable, when its size is not a
/// multiple of 16 or holds more than limits::kMaxScanPoints records (checked before reading),
/// and when every record has a non-finite value (an empty file gives an empty cloud).
VelodyneReadStats loadVelodyneBin(const std::string& path, pcl::PointCloud<pcl::PointXYZI>& cloud);

/// Writes a cloud as a KITTI Velodyne .bin, atomically.
void saveVelodyneBin(const std::string& path, const pcl::PointCloud<pcl::PointXYZI>& cloud);

} // namespace msf
