// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/tsdf_integrator.h>

#include <pcl/type_traits.h>

#include <cmath>

namespace msf {

// Thin and header-only: it only gathers the points; the work is in integrateRays.
template <typename PointT>
void TsdfIntegrator::integrateScan(const pcl::PointCloud<PointT>& points_sensor,
                                   const Eigen::Isometry3d& T_world_sensor) {
  constexpr bool kHasRgb = pcl::traits::has_field<PointT, pcl::fields::rgb>::value ||
                           pcl::traits::has_field<PointT, pcl::fields::rgba>::value;
  const Eigen::Isometry3f T = T_world_sensor.cast<float>();
  std::vector<Eigen::Vector3f> points_world;
  std::vector<cv::Vec3b> colors;
  points_world.reserve(points_sensor.size());
  if constexpr (kHasRgb)
    colors.reserve(points_sensor.size());
  for (const PointT& p : points_sensor) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      continue;
    points_world.push_back(T * Eigen::Vector3f(p.x, p.y, p.z));
    if constexpr (kHasRgb)
      colors.emplace_back(p.b, p.g, p.r);
  }
  integrateRays(points_world, colors, T_world_sensor.translation());
}

} // namespace msf
