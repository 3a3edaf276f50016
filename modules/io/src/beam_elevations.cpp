// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/beam_elevations.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  // A beam's returns lie at one elevation: rings whose returns spread wider are not beams.
  constexpr double kBeamSpreadDeg = 1.0;
  std::vector<double> elevations;
  std::vector<std::uint16_t> kept;
  for (auto& [ring, values] : by_ring) {
    if (values.size() < min_points)
      continue;
    std::sort(values.begin(), values.end());
    if (values[values.size() * 3 / 4] - values[values.size() / 4] > kBeamSpreadDeg)
      return {};
    elevations.push_back(values[values.size() / 2]);
    kept.push_back(ring);
  }
  // A beam missing between two others would widen the spacing the stages take from the list.
  if (elevations.size() < 2 || kept.back() - kept.front() + 1u != kept.size())
    return {};
  std::sort(elevations.begin(), elevations.end()); // drivers number rings top first or bottom first
  return elevations;
}

std::string beamsFromRingsNote(const std::vector<double>& beams) {
  char text[200];
  std::snprintf(text, sizeof text,
                "%zu beams from the first scan's rings, %.1f to %.1f degrees (a rig file's lidar.beam_elevations_deg "
                "sets them)",
                beams.size(), beams.empty() ? 0.0 : beams.front(), beams.empty() ? 0.0 : beams.back());
  return text;
}

} // namespace msf
