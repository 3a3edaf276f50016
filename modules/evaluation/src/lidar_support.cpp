// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/lidar_support.h>

#include <cmath>
#include <string>

namespace msf {

LidarSupport::LidarSupport(double cell_m) : cell_(static_cast<float>(cell_m)) {
  if (!(cell_m > 0.0) || !std::isfinite(cell_m))
    throw InvalidInputError("LiDAR support: the cell must be > 0 m, not " + std::to_string(cell_m));
}

Eigen::Vector3i LidarSupport::cellOf(const Eigen::Vector3f& p) const {
  return (p / cell_).array().floor().cast<int>();
}

void LidarSupport::addPoint(const Eigen::Vector3f& world) {
  if (world.allFinite())
    cells_.insert(cellOf(world));
}

void LidarSupport::addScan(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  for (const auto& point : scan.points)
    if (point.getVector3fMap().squaredNorm() > 1e-6f) // a return at the sensor is none
      addPoint(T * point.getVector3fMap());
}

bool LidarSupport::supports(const Eigen::Vector3f& p) const {
  if (!p.allFinite())
    return false;
  const Eigen::Vector3i c = cellOf(p);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz)
        if (cells_.count(c + Eigen::Vector3i(dx, dy, dz)))
          return true;
  return false;
}

} // namespace msf
