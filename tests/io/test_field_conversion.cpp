// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>

#include "test_support.h"

#include <pcl/point_types.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace {

using msf::test::errorOf;

/// A binary .pcd of 3 points whose fields have the given TYPE and SIZE letters, values as raw bytes.
template <typename T>
std::string pcdOf(const msf::test::TempDir& dir, const std::string& fields, const std::string& size,
                  const std::string& type, const std::vector<T>& values) {
  const std::size_t n = std::count(fields.begin(), fields.end(), ' ') + 1;
  std::string count;
  for (std::size_t i = 0; i < n; ++i)
    count += i ? " 1" : "1";
  const std::string path = dir.file("c.pcd");
  std::ofstream out(path, std::ios::binary);
  out << "VERSION 0.7\nFIELDS " << fields << "\nSIZE " << size << "\nTYPE " << type << "\nCOUNT " << count
      << "\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA binary\n";
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T)));
  return path;
}

TEST(FieldConversion, Int32AndFloat64CoordinatesAreReadAsTheirValuesNotZeros) {
  // PCL's conversion reads an x of another type than the point's float32 as 0, with a warning.
  msf::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  msf::loadCloud(pcdOf<std::int32_t>(dir, "x y z", "4 4 4", "I I I", {1, 2, 3, -4, 5, 60000, 7, 8, 9}), cloud);
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud[1].x, -4.f);
  EXPECT_EQ(cloud[1].z, 60000.f);
  msf::loadCloud(pcdOf<double>(dir, "x y z", "8 8 8", "F F F", {0.5, 1.25, 5.0, 1, 2, 3, -7.5, 8, 1e30}), cloud);
  EXPECT_EQ(cloud[0].y, 1.25f);
  EXPECT_EQ(cloud[2].x, -7.5f);
  EXPECT_EQ(cloud[2].z, 1e30f);
}

TEST(FieldConversion, OtherFieldsAreConvertedAndColourKeepsItsBits) {
  msf::test::TempDir dir;
  // intensity as a uint8 (a common LiDAR .pcd), as the last field, 13 bytes a point.
  std::vector<std::uint8_t> raw;
  for (int i = 0; i < 3; ++i) {
    const float xyz[3] = {1.f * i, 2.f, 3.f};
    raw.insert(raw.end(), reinterpret_cast<const std::uint8_t*>(xyz), reinterpret_cast<const std::uint8_t*>(xyz) + 12);
    raw.push_back(static_cast<std::uint8_t>(100 + i));
  }
  pcl::PointCloud<pcl::PointXYZI> cloud;
  msf::loadCloud(pcdOf<std::uint8_t>(dir, "x y z intensity", "4 4 4 1", "F F F U", raw), cloud);
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud[2].x, 2.f);
  EXPECT_EQ(cloud[2].intensity, 102.f);
  // rgb written as U 4 (a packed colour): the same bits, not the integer's value as a float.
  const std::uint32_t colour = 0x00ff8040;
  std::vector<std::uint32_t> packed;
  for (int i = 0; i < 3; ++i) {
    const float xyz[3] = {1.f, 2.f, 3.f};
    std::uint32_t words[3];
    std::memcpy(words, xyz, 12);
    packed.insert(packed.end(), {words[0], words[1], words[2], colour});
  }
  pcl::PointCloud<pcl::PointXYZRGB> rgb;
  msf::loadCloud(pcdOf<std::uint32_t>(dir, "x y z rgb", "4 4 4 4", "F F F U", packed), rgb);
  EXPECT_EQ(rgb[1].r, 0xff);
  EXPECT_EQ(rgb[1].g, 0x80);
  EXPECT_EQ(rgb[1].b, 0x40);
}

TEST(FieldConversion, AValueTheTypeCannotHoldIsRefusedByName) {
  msf::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  const std::string path = pcdOf<double>(dir, "x y z", "8 8 8", "F F F", {1, 2, 3, 4, 5, 1e300, 7, 8, 9});
  EXPECT_EQ(errorOf([&] { msf::loadCloud(path, cloud); }),
            "cloud '" + path + "': field 'z' (float64) of point 1 is 1e+300, which float32 cannot hold");
}

} // namespace
