// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/beam_elevations.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace msf {

std::vector<double> beamElevationsFromRings(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                            const std::vector<std::uint16_t>& rings, std::size_t min_points) {
  if (rings.size() != scan.size())
    return {};
  std::map<std::uint16_t, std::vector<double>> by_ring;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const pcl::PointXYZI& p = scan[i];
    by_ring[rings[i]].push_back(std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI);
  }
  std::vector<double> elevations;
  for (auto& [ring, values] : by_ring) {
    if (values.size() < min_points)
      continue;
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    elevations.push_back(values[values.size() / 2]);
  }
  if (elevations.size() < 2)
    return {};
  std::sort(elevations.begin(), elevations.end()); // drivers number rings top first or bottom first
  return elevations;
}

} // namespace msf
