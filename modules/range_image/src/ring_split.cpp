#include <msf/common/exceptions.h>
#include <msf/range_image/ring_split.h>

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

int splitRings(const pcl::PointCloud<pcl::PointXYZI>& scan, const RingSplitConfig& config,
               pcl::PointCloud<pcl::PointXYZI>& input, pcl::PointCloud<pcl::PointXYZI>& heldout) {
  config.validate();
  const std::vector<int> ids = ringIds(scan);
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
  return ids.empty() ? 0 : ids.back() + 1;
}

} // namespace msf
