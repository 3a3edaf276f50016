// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/range_image/ring_split.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

void RingSplitConfig::validate() const {
  checkKeyRanges(*this);
  if (heldout_remainder >= modulo)
    throw ConfigError("rings.heldout_remainder must be 0.." + std::to_string(modulo - 1) + ", not " +
                      std::to_string(heldout_remainder));
}

std::vector<int> ringIds(const pcl::PointCloud<pcl::PointXYZI>& scan) {
  std::vector<int> ids(scan.size());
  int ring = 0;
  float previous = 0.f;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const float azimuth = std::atan2(scan[i].y, scan[i].x);
    if (i > 0 && azimuth - previous < -static_cast<float>(M_PI))
      ++ring;
    previous = azimuth;
    ids[i] = ring;
  }
  return ids;
}

std::vector<int> ringIdsFromElevations(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                       const std::vector<double>& elevations_deg) {
  if (elevations_deg.empty())
    throw InvalidInputError("ring ids from elevations: the LiDAR's beam elevations are not given");
  std::vector<int> ids(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const auto& p = scan[i];
    const double elevation = std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI;
    // The nearest beam: the first above, or the one below it when that is nearer.
    const auto above = std::lower_bound(elevations_deg.begin(), elevations_deg.end(), elevation);
    auto nearest = above == elevations_deg.end() ? above - 1 : above;
    if (above != elevations_deg.begin() && above != elevations_deg.end() && elevation - above[-1] < *above - elevation)
      nearest = above - 1;
    ids[i] = static_cast<int>(nearest - elevations_deg.begin());
  }
  return ids;
}

int splitRings(const pcl::PointCloud<pcl::PointXYZI>& scan, const RingSplitConfig& config,
               pcl::PointCloud<pcl::PointXYZI>& input, pcl::PointCloud<pcl::PointXYZI>& heldout) {
  return splitRings(scan, ringIds(scan), config, input, heldout);
}

int splitRings(const pcl::PointCloud<pcl::PointXYZI>& scan, const std::vector<int>& ids, const RingSplitConfig& config,
               pcl::PointCloud<pcl::PointXYZI>& input, pcl::PointCloud<pcl::PointXYZI>& heldout) {
  config.validate();
  if (ids.size() != scan.size())
    throw InvalidInputError("ring split: " + std::to_string(ids.size()) + " ring ids for a scan of " +
                            std::to_string(scan.size()) + " points");
  pcl::PointCloud<pcl::PointXYZI> in, out; // the outputs may alias the scan
  in.reserve(scan.size());
  out.reserve(scan.size() / static_cast<std::size_t>(config.modulo) + 1);
  for (std::size_t i = 0; i < scan.size(); ++i)
    (config.isHeldOut(ids[i]) ? out : in).push_back(scan[i]);
  for (auto* part : {&in, &out}) {
    part->header = scan.header;
    part->sensor_origin_ = scan.sensor_origin_;
    part->sensor_orientation_ = scan.sensor_orientation_;
    part->is_dense = scan.is_dense;
  }
  input.swap(in);
  heldout.swap(out);
  return ids.empty() ? 0 : *std::max_element(ids.begin(), ids.end()) + 1;
}

} // namespace msf
