// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/exceptions.h>
#include <msf/io/pinhole_camera.h>

#include <cmath>

namespace msf {

template <typename PointT>
PinholeFit fitPinhole(const pcl::PointCloud<PointT>& cloud) {
  PinholeFit fit;
  for (std::uint32_t v = 0; v < cloud.height; ++v)
    for (std::uint32_t u = 0; u < cloud.width; ++u) {
      const PointT& p = cloud[static_cast<std::size_t>(v) * cloud.width + u];
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.z > 0.f)
        fit.add(u, v, p.x, p.y, p.z);
    }
  return fit;
}

template <typename PointT>
PinholeCamera estimatePinholeCamera(const pcl::PointCloud<PointT>& cloud, double max_rms_px) {
  if (!cloud.isOrganized() || cloud.empty())
    throw InvalidInputError("expected an organized cloud (height > 1) to recover the camera, got " +
                            std::to_string(cloud.width) + "x" + std::to_string(cloud.height));
  return fitPinhole(cloud).solve(static_cast<int>(cloud.width), static_cast<int>(cloud.height),
                                 "organized cloud " + std::to_string(cloud.width) + "x" + std::to_string(cloud.height),
                                 max_rms_px);
}

} // namespace msf
