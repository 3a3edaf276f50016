// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/io/scan_file.h>
#include <msf/io/velodyne_io.h>

#include <pcl/PCLPointCloud2.h>

#include <cmath>
#include <cstring>
#include <optional>

namespace msf {

namespace {

/// A field of a cloud blob read as double, whatever its numeric type.
class FieldReader {
public:
  FieldReader(const pcl::PCLPointField& field) : offset_(field.offset), type_(field.datatype) {}
  double operator()(const std::uint8_t* point) const {
    const std::uint8_t* p = point + offset_;
    switch (type_) {
    case pcl::PCLPointField::INT8: return read<std::int8_t>(p);
    case pcl::PCLPointField::UINT8: return read<std::uint8_t>(p);
    case pcl::PCLPointField::INT16: return read<std::int16_t>(p);
    case pcl::PCLPointField::UINT16: return read<std::uint16_t>(p);
    case pcl::PCLPointField::INT32: return read<std::int32_t>(p);
    case pcl::PCLPointField::UINT32: return read<std::uint32_t>(p);
    case pcl::PCLPointField::FLOAT32: return read<float>(p);
    case pcl::PCLPointField::FLOAT64: return read<double>(p);
    default: return std::nan("");
    }
  }
  bool isInteger() const { return type_ != pcl::PCLPointField::FLOAT32 && type_ != pcl::PCLPointField::FLOAT64; }

private:
  template <typename T>
  static double read(const std::uint8_t* p) {
    T value;
    std::memcpy(&value, p, sizeof value);
    return static_cast<double>(value);
  }
  std::uint32_t offset_;
  std::uint8_t type_;
};

std::optional<FieldReader> field(const pcl::PCLPointCloud2& blob, std::initializer_list<const char*> names) {
  for (const char* name : names)
    for (const auto& f : blob.fields)
      if (f.name == name && f.count >= 1)
        return FieldReader(f);
  return std::nullopt;
}

ScanFile fromBlob(const pcl::PCLPointCloud2& blob, const std::string& path) {
  const auto x = field(blob, {"x"}), y = field(blob, {"y"}), z = field(blob, {"z"});
  if (!x || !y || !z)
    throw IOError("scan '" + path + "' has no field " + (!x ? "x" : !y ? "y" : "z") + " (a scan needs x y z)");
  const auto intensity = field(blob, {"intensity", "reflectivity", "i"});
  const auto ring = field(blob, {"ring"});
  const auto time = field(blob, {"time", "t", "timestamp"});
  ScanFile scan;
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint8_t* p = blob.data.data() + k * blob.point_step;
    pcl::PointXYZI point;
    point.x = static_cast<float>((*x)(p));
    point.y = static_cast<float>((*y)(p));
    point.z = static_cast<float>((*z)(p));
    point.intensity = intensity ? static_cast<float>((*intensity)(p)) : 0.f;
    if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z))
      continue;
    scan.points.push_back(point);
    if (ring)
      scan.ring.push_back(static_cast<std::uint16_t>((*ring)(p)));
    if (time) // an integer time field counts nanoseconds (Ouster's, Hesai's)
      scan.time_s.push_back(static_cast<float>(time->isInteger() ? (*time)(p) * 1e-9 : (*time)(p)));
  }
  return scan;
}

} // namespace

ScanFile loadScanFile(const std::string& path) {
  const std::string ext = fileExtension(path);
  ScanFile scan;
  if (ext == ".bin") {
    loadVelodyneBin(path, scan.points);
  } else if (ext == ".pcd" || ext == ".ply") {
    pcl::PCLPointCloud2 blob;
    loadCloudBlob(path, blob);
    scan = fromBlob(blob, path);
  } else {
    throw IOError("scan '" + path + "': a scan is a .bin (KITTI), .pcd or .ply file");
  }
  if (scan.points.empty())
    throw IOError("scan '" + path + "' has no finite point");
  scan.points.width = static_cast<std::uint32_t>(scan.points.size());
  scan.points.height = 1;
  scan.points.is_dense = true;
  return scan;
}

} // namespace msf
