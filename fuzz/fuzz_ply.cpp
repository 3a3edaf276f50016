// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The PLY readers: msf::loadCloud and msf::loadMesh on .ply files, with inputs up to 256 KB
// (make fuzz) so that headers reach the 64 KB the header check reads. The first byte picks
// the reader (even: cloud, odd: mesh), the rest is the file.
#include "fuzz_input.h"

#include <msf/io/cloud_io.h>

#include <pcl/PolygonMesh.h>
#include <pcl/point_types.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  const bool mesh = data[0] & 1;
  const std::string path = msf::fuzz::writeInput("input.ply", data + 1, size - 1);
  msf::fuzz::expectOnlyLibraryErrors([&] {
    if (mesh) {
      pcl::PolygonMesh polygons;
      msf::loadMesh(path, polygons);
    } else {
      pcl::PointCloud<pcl::PointXYZRGB> cloud;
      msf::loadCloud(path, cloud);
    }
  });
  return 0;
}
