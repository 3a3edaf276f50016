// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The KITTI velodyne .bin reader (x y z reflectance float32 records).
#include "fuzz_input.h"

#include <msf/io/velodyne_io.h>

#include <pcl/point_types.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = msf::fuzz::writeInput("scan.bin", data, size);
  msf::fuzz::expectOnlyLibraryErrors([&] {
    pcl::PointCloud<pcl::PointXYZI> cloud;
    msf::loadVelodyneBin(path, cloud);
  });
  return 0;
}
