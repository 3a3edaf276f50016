// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// PCD and PLY header and body readers (msf::loadCloudBlob, msf::loadCloud). The first byte
// picks the format, the rest is the file.
#include "fuzz_input.h"

#include <msf/io/cloud_io.h>

#include <pcl/point_types.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  const bool ply = data[0] & 1;
  const std::string path = msf::fuzz::writeInput(ply ? "cloud.ply" : "cloud.pcd", data + 1, size - 1);
  msf::fuzz::expectOnlyLibraryErrors([&] {
    pcl::PointCloud<pcl::PointXYZI> cloud;
    msf::loadCloud(path, cloud);
  });
  return 0;
}
