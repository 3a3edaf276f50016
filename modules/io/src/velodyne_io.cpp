// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/io/velodyne_io.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

namespace msf {

VelodyneReadStats loadVelodyneBin(const std::string& path, pcl::PointCloud<pcl::PointXYZI>& cloud) {
  requireFile(path, "scan");
  const auto bytes = std::filesystem::file_size(path);
  constexpr std::size_t kRecord = 4 * sizeof(float);
  if (bytes % kRecord != 0)
    throw IOError("scan '" + path + "' has " + std::to_string(bytes) +
                  " bytes, not a multiple of 16 (float32 x, y, z, reflectance): truncated or not a KITTI .bin");
  if (bytes / kRecord > limits::kMaxScanPoints)
    throw IOError("scan '" + path + "' has " + std::to_string(bytes / kRecord) + " records (" + std::to_string(bytes) +
                  " bytes), more than the " + std::to_string(limits::kMaxScanPoints) +
                  " a scan may hold: not one LiDAR scan");
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file)
    throw IOError("scan '" + path + "' cannot be opened");
  VelodyneReadStats stats;
  stats.records = bytes / kRecord;
  std::vector<float> raw(stats.records * 4);
  if (std::fread(raw.data(), kRecord, stats.records, file.get()) != stats.records)
    throw IOError("scan '" + path + "' could not be read completely");

  cloud.clear();
  cloud.reserve(stats.records);
  for (std::size_t i = 0; i < stats.records; ++i) {
    const float* r = &raw[4 * i];
    if (!std::isfinite(r[0]) || !std::isfinite(r[1]) || !std::isfinite(r[2]) || !std::isfinite(r[3])) {
      ++stats.dropped_nonfinite;
      continue;
    }
    pcl::PointXYZI p;
    p.x = r[0];
    p.y = r[1];
    p.z = r[2];
    p.intensity = r[3];
    cloud.push_back(p);
  }
  // Said as such: the tools would otherwise report a scan that lands nowhere (a wrong calibration).
  if (cloud.empty() && stats.records > 0)
    throw IOError("scan '" + path + "': each of its " + std::to_string(stats.records) +
                  " records has a value that is not finite (NaN or inf in x, y, z or reflectance)");
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  return stats;
}

void saveVelodyneBin(const std::string& path, const pcl::PointCloud<pcl::PointXYZI>& cloud) {
  std::vector<float> raw;
  raw.reserve(cloud.size() * 4);
  for (const auto& p : cloud) {
    raw.insert(raw.end(), {p.x, p.y, p.z, p.intensity});
  }
  writeBytesAtomically(path, raw.data(), raw.size() * sizeof(float));
}

} // namespace msf
