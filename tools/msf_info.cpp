// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Prints what a .pcd holds: size, organization, fields, valid points, depth range.
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/cloud_io.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace {

const char* typeName(std::uint8_t datatype) {
  switch (datatype) {
  case pcl::PCLPointField::INT8: return "int8";
  case pcl::PCLPointField::UINT8: return "uint8";
  case pcl::PCLPointField::INT16: return "int16";
  case pcl::PCLPointField::UINT16: return "uint16";
  case pcl::PCLPointField::INT32: return "int32";
  case pcl::PCLPointField::UINT32: return "uint32";
  case pcl::PCLPointField::FLOAT32: return "float32";
  case pcl::PCLPointField::FLOAT64: return "float64";
  default: return "?";
  }
}

void describe(const std::string& path) {
  pcl::PCLPointCloud2 blob;
  msf::loadCloudBlob(path, blob);
  const bool organized = blob.height > 1;
  std::printf("%s\n", path.c_str());
  std::printf("  points:     %zu (%u x %u)\n", static_cast<std::size_t>(blob.width) * blob.height, blob.width, blob.height);
  std::printf("  organized:  %s\n", organized ? "yes" : "no");
  std::printf("  dense:      %s\n", blob.is_dense ? "yes" : "no");
  std::printf("  fields:    ");
  for (const auto& f : blob.fields)
    std::printf(" %s(%s%s)", f.name.c_str(), typeName(f.datatype),
                f.count > 1 ? ("x" + std::to_string(f.count)).c_str() : "");
  std::printf("\n");
  const bool has_xyz = pcl::getFieldIndex(blob, "x") >= 0 && pcl::getFieldIndex(blob, "y") >= 0 &&
                       pcl::getFieldIndex(blob, "z") >= 0;
  if (!has_xyz)
    return;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  msf::fromCloudBlob(blob, cloud, path);
  std::size_t valid = 0;
  float zmin = std::numeric_limits<float>::max(), zmax = -zmin, rmin = zmin, rmax = -zmin;
  for (const auto& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      continue;
    ++valid;
    const float r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z);
    rmin = std::min(rmin, r), rmax = std::max(rmax, r);
  }
  std::printf("  valid:      %zu (%.1f %%)\n", valid, cloud.empty() ? 0.0 : 100.0 * valid / cloud.size());
  if (valid > 0) {
    std::printf("  depth z:    %.3f .. %.3f m\n", zmin, zmax);
    std::printf("  range:      %.3f .. %.3f m\n", rmin, rmax);
  }
}

} // namespace

int main(int argc, char** argv) {
  msf::tool::CommandLine cli(
      "msf_info", "<file.pcd|.ply> [more ...]",
      "Prints size, organization, fields, valid (finite) points and the depth range of each cloud.");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& paths) {
    for (const auto& path : paths)
      describe(path);
    return 0;
  });
}
