// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/io/velodyne_io.h>

#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

namespace {

std::string scan0() { return msf::test::kittiDir() + "/odometry/sequences/04/velodyne/000000.bin"; }

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeRecords(const std::string& path, const std::vector<float>& values) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(values.data()),
                                              static_cast<std::streamsize>(values.size() * sizeof(float)));
}

TEST(VelodyneIo, RealScanKeepsFileOrderAndCount) {
  MSF_REQUIRE_KITTI();
  pcl::PointCloud<pcl::PointXYZI> cloud;
  const auto stats = msf::loadVelodyneBin(scan0(), cloud);
  EXPECT_EQ(stats.records, std::filesystem::file_size(scan0()) / 16);
  EXPECT_EQ(cloud.size() + stats.dropped_nonfinite, stats.records);
  EXPECT_GT(cloud.size(), 100000u);
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_TRUE(cloud.is_dense);
  // First record, read independently.
  std::ifstream in(scan0(), std::ios::binary);
  float first[4];
  in.read(reinterpret_cast<char*>(first), sizeof first);
  EXPECT_EQ(cloud[0].x, first[0]);
  EXPECT_EQ(cloud[0].intensity, first[3]);
}

TEST(VelodyneIo, BinToPcdToBinIsByteIdentical) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZI> cloud, back;
  msf::loadVelodyneBin(scan0(), cloud);
  msf::saveCloud(dir.file("scan.pcd"), cloud);
  msf::loadCloud(dir.file("scan.pcd"), back);
  ASSERT_EQ(back.size(), cloud.size());
  msf::saveVelodyneBin(dir.file("scan.bin"), back);
  EXPECT_EQ(readBytes(dir.file("scan.bin")), readBytes(scan0()));
}

TEST(VelodyneIo, NonFiniteRecordsAreDroppedAndCounted) {
  msf::test::TempDir dir;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  writeRecords(dir.file("s.bin"), {1, 2, 3, 0.5f, nan, 0, 0, 0, 4, 5, 6, 0.25f, 0, inf, 0, 0});
  pcl::PointCloud<pcl::PointXYZI> cloud;
  const auto stats = msf::loadVelodyneBin(dir.file("s.bin"), cloud);
  EXPECT_EQ(stats.records, 4u);
  EXPECT_EQ(stats.dropped_nonfinite, 2u);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud[1].y, 5.f);
  EXPECT_EQ(cloud[1].intensity, 0.25f);
}

TEST(VelodyneIo, AScanOfOnlyNonFiniteRecordsSaysSo) {
  // NaN reflectance everywhere: every record dropped, and the tools blamed the calibration.
  msf::test::TempDir dir;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  writeRecords(dir.file("s.bin"), {1, 2, 3, nan, 4, 5, 6, nan});
  pcl::PointCloud<pcl::PointXYZI> cloud;
  EXPECT_EQ(msf::test::errorOf([&] { msf::loadVelodyneBin(dir.file("s.bin"), cloud); }),
            "scan '" + dir.file("s.bin") + "': each of its 2 records has a value that is not finite (NaN or inf in x, "
            "y, z or reflectance)");
  writeRecords(dir.file("empty.bin"), {});
  EXPECT_EQ(msf::loadVelodyneBin(dir.file("empty.bin"), cloud).records, 0u);
  EXPECT_TRUE(cloud.empty());
}

TEST(VelodyneIo, AFileTooLargeForAScanIsRefusedBeforeItIsRead) {
  // 2 GB of holes: read whole before anything looked at it.
  msf::test::TempDir dir;
  { std::ofstream(dir.file("huge.bin")); }
  std::filesystem::resize_file(dir.file("huge.bin"), std::uintmax_t{2} << 30);
  pcl::PointCloud<pcl::PointXYZI> cloud;
  EXPECT_EQ(msf::test::errorOf([&] { msf::loadVelodyneBin(dir.file("huge.bin"), cloud); }),
            "scan '" + dir.file("huge.bin") + "' has 134217728 records (2147483648 bytes), more than the 16777216 a "
            "scan may hold: not one LiDAR scan");
}

TEST(VelodyneIo, TruncatedFileNamesFileAndSize) {
  msf::test::TempDir dir;
  writeRecords(dir.file("cut.bin"), std::vector<float>(250, 1.f)); // 1000 bytes
  pcl::PointCloud<pcl::PointXYZI> cloud;
  try {
    msf::loadVelodyneBin(dir.file("cut.bin"), cloud);
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file("cut.bin")), std::string::npos) << what;
    EXPECT_NE(what.find("1000 bytes"), std::string::npos) << what;
  }
}

TEST(VelodyneIo, MissingFileAndUnwritableOutput) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  EXPECT_THROW(msf::loadVelodyneBin("/nonexistent/scan.bin", cloud), msf::IOError);
  cloud.push_back(pcl::PointXYZI(1.f));
  EXPECT_THROW(msf::saveVelodyneBin("/nonexistent/scan.bin", cloud), msf::IOError);
  EXPECT_THROW(msf::saveCloud("/nonexistent/scan.pcd", cloud), msf::IOError);
}

TEST(CloudIo, MissingFieldIsNamed) {
  msf::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZ> xyz;
  xyz.push_back(pcl::PointXYZ(1, 2, 3));
  msf::saveCloud(dir.file("xyz.pcd"), xyz);
  pcl::PointCloud<pcl::PointXYZI> with_intensity;
  try {
    msf::loadCloud(dir.file("xyz.pcd"), with_intensity);
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("'intensity'"), std::string::npos) << e.what();
  }
}

TEST(CloudIo, GarbageAndEmptyInputs) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("bad.pcd")) << "not a point cloud\n";
  pcl::PointCloud<pcl::PointXYZ> cloud;
  EXPECT_THROW(msf::loadCloud(dir.file("bad.pcd"), cloud), msf::IOError);
  EXPECT_THROW(msf::saveCloud(dir.file("empty.pcd"), cloud), msf::InvalidInputError);
  EXPECT_FALSE(msf::test::fileExists(dir.file("empty.pcd")));
}

} // namespace
