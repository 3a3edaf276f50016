// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// writeCompressedPcd against PCL's own binary_compressed writer: byte for byte for a body of one
// piece (1 MiB), and read back by PCL's reader beyond.
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/io/compressed_pcd.h>
#include <msf/io/impl/cloud_io.hpp>

#include "test_support.h"

#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <opencv2/core/utility.hpp>

#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

namespace {

/// `n` points of PointXYZRGBNormal (fields with padding between them), values of a noisy surface.
pcl::PointCloud<pcl::PointXYZRGBNormal> surfaceCloud(std::size_t n) {
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.01f);
  for (std::size_t i = 0; i < n; ++i) {
    pcl::PointXYZRGBNormal p;
    p.x = 0.1f * static_cast<float>(i % 100);
    p.y = 0.1f * static_cast<float>(i / 100);
    p.z = 2.f + noise(rng);
    p.r = static_cast<std::uint8_t>(i % 256);
    p.g = 100;
    p.b = 7;
    p.normal_x = noise(rng);
    p.normal_y = 0.f;
    p.normal_z = 1.f;
    p.curvature = noise(rng);
    cloud.push_back(p);
  }
  cloud.sensor_origin_ = Eigen::Vector4f(1, 2, 3, 0);
  return cloud;
}

pcl::PCLPointCloud2 surfaceBlob(std::size_t n) {
  pcl::PCLPointCloud2 blob;
  pcl::toPCLPointCloud2(surfaceCloud(n), blob);
  return blob;
}

std::string pclWrites(const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin) {
  std::ostringstream out;
  EXPECT_EQ(pcl::PCDWriter().writeBinaryCompressed(out, blob, origin, Eigen::Quaternionf::Identity()), 0);
  return out.str();
}

std::string weWrite(const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin, const std::string& comment = "") {
  std::ostringstream out;
  msf::writeCompressedPcd(out, blob, origin, Eigen::Quaternionf::Identity(), comment);
  return out.str();
}

TEST(CompressedPcd, TheBytesArePclsOwn) {
  const Eigen::Vector4f origin(1, 2, 3, 0);
  for (std::size_t n : {0u, 1u, 5000u}) {
    const pcl::PCLPointCloud2 blob = surfaceBlob(n);
    const std::string expected = pclWrites(blob, origin), written = weWrite(blob, origin);
    EXPECT_GT(written.size(), 100u);
    EXPECT_TRUE(written == expected) << n << " points: " << written.size() << " bytes against PCL's "
                                     << expected.size();
    // The cloud itself, read where it lies, gives the same bytes.
    const pcl::PointCloud<pcl::PointXYZRGBNormal> cloud = surfaceCloud(n);
    std::ostringstream from_cloud;
    msf::writeCompressedPcd(from_cloud, cloud);
    EXPECT_TRUE(from_cloud.str() == expected) << n << " points, from the cloud";
  }
}

TEST(CompressedPcd, ACommentFollowsTheFirstLineAndPclReadsThePointsBack) {
  const pcl::PCLPointCloud2 blob = surfaceBlob(3000);
  const std::string comment = "# made by a test\n";
  const std::string written = weWrite(blob, Eigen::Vector4f::Zero(), comment);
  std::string expected = pclWrites(blob, Eigen::Vector4f::Zero());
  expected.insert(expected.find('\n') + 1, comment);
  EXPECT_TRUE(written == expected);

  msf::test::TempDir dir;
  msf::saveCloudBlob(dir.file("c.pcd"), blob);
  pcl::PointCloud<pcl::PointXYZRGBNormal> back, original;
  pcl::fromPCLPointCloud2(blob, original);
  msf::loadCloud(dir.file("c.pcd"), back);
  ASSERT_EQ(back.size(), original.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].z, original[i].z);
    EXPECT_EQ(back[i].rgba, original[i].rgba);
    EXPECT_EQ(back[i].curvature, original[i].curvature);
  }
}

TEST(CompressedPcd, ALargeBodyIsCompressedInPiecesThatPclReadsBackOnAnyNumberOfThreads) {
  // 40 000 points of 8 fields of 4 bytes: 1.28 MB of body, two pieces.
  const pcl::PCLPointCloud2 blob = surfaceBlob(40000);
  const std::string written = weWrite(blob, Eigen::Vector4f::Zero());
  EXPECT_FALSE(written == pclWrites(blob, Eigen::Vector4f::Zero())); // PCL compresses it as one piece
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const std::string on_one_thread = weWrite(blob, Eigen::Vector4f::Zero());
  cv::setNumThreads(threads);
  EXPECT_TRUE(written == on_one_thread);

  msf::test::TempDir dir;
  std::ofstream(dir.file("c.pcd"), std::ios::binary) << written;
  pcl::PointCloud<pcl::PointXYZRGBNormal> back, original;
  pcl::fromPCLPointCloud2(blob, original);
  ASSERT_EQ(pcl::io::loadPCDFile(dir.file("c.pcd"), back), 0); // PCL's reader, not ours
  ASSERT_EQ(back.size(), original.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < back.size(); ++i)
    differ += back[i].x != original[i].x || back[i].z != original[i].z || back[i].rgba != original[i].rgba ||
              back[i].normal_x != original[i].normal_x || back[i].curvature != original[i].curvature;
  EXPECT_EQ(differ, 0u);
}

/// The body read by readCompressedPieces after PCL's readHeader; false as it returns.
bool readInPieces(const std::string& path, pcl::PCLPointCloud2& blob) {
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  EXPECT_EQ(pcl::PCDReader().readHeader(path, blob, origin, orientation, version, data_type, data_index), 0);
  return msf::readCompressedPieces(path, data_index, blob);
}

void expectSameAsPclReads(const pcl::PCLPointCloud2& blob, const std::string& path) {
  pcl::PCLPointCloud2 pcls;
  ASSERT_EQ(pcl::PCDReader().read(path, pcls), 0);
  EXPECT_EQ(blob.width, pcls.width);
  EXPECT_EQ(blob.height, pcls.height);
  EXPECT_EQ(blob.point_step, pcls.point_step);
  EXPECT_EQ(pcl::getFieldsList(blob), pcl::getFieldsList(pcls));
  EXPECT_EQ(blob.is_dense, pcls.is_dense);
  EXPECT_TRUE(blob.data == pcls.data) << "the points differ from PCL's reading";
}

TEST(CompressedPcd, ALargeBodyIsReadInPiecesAsPclReadsIt) {
  // 70 000 points of 32 bytes: three pieces. A value that is not finite, in the last piece,
  // makes the cloud not dense, as PCL's reader says (an alpha of 0: rgb, a float field, finite).
  for (const bool with_nan : {false, true}) {
    pcl::PointCloud<pcl::PointXYZRGBNormal> cloud = surfaceCloud(70000);
    for (auto& p : cloud)
      p.a = 0;
    if (with_nan)
      cloud[69000].curvature = std::numeric_limits<float>::quiet_NaN();
    msf::test::TempDir dir;
    const std::string path = dir.file("c.pcd");
    msf::saveCloud(path, cloud);
    pcl::PCLPointCloud2 blob;
    ASSERT_TRUE(readInPieces(path, blob)) << "the pieces were not found";
    EXPECT_EQ(blob.is_dense, !with_nan);
    expectSameAsPclReads(blob, path);
    const int threads = cv::getNumThreads();
    cv::setNumThreads(1);
    pcl::PCLPointCloud2 on_one_thread;
    msf::loadCloudBlob(path, on_one_thread);
    cv::setNumThreads(threads);
    expectSameAsPclReads(on_one_thread, path);
  }
}

TEST(CompressedPcd, AValueThatAPieceEndsWithinIsWrittenAndReadWhole) {
  // A field of three floats: the first piece ends within one of its values (its plane begins
  // at 400 004 bytes; 1 MiB is no multiple of 12 bytes from there).
  pcl::PCLPointCloud2 blob;
  blob.fields = {{"x", 0, pcl::PCLPointField::FLOAT32, 1}, {"v", 4, pcl::PCLPointField::FLOAT32, 3}};
  blob.width = 100001, blob.height = 1, blob.point_step = 16, blob.row_step = 16 * blob.width;
  blob.data.resize(static_cast<std::size_t>(blob.row_step));
  for (std::size_t i = 0; i < blob.data.size() / 4; ++i) {
    const float value = 0.001f * static_cast<float>(i % 7919);
    std::memcpy(&blob.data[i * 4], &value, 4);
  }
  msf::test::TempDir dir;
  const std::string path = dir.file("c.pcd");
  std::ofstream(path, std::ios::binary) << weWrite(blob, Eigen::Vector4f::Zero());
  pcl::PCLPointCloud2 back;
  ASSERT_TRUE(readInPieces(path, back));
  EXPECT_TRUE(back.data == blob.data) << "read in pieces";
  expectSameAsPclReads(back, path); // PCL's reader, the one stream whole
}

TEST(CompressedPcd, PiecesTheHeaderMisplacesAreLeftToPclsReader) {
  msf::test::TempDir dir;
  const std::string path = dir.file("c.pcd");
  msf::saveCloud(path, surfaceCloud(70000));
  std::stringstream text;
  text << std::ifstream(path, std::ios::binary).rdbuf();
  const std::string file = text.str(), tag = "# msfusion lzf_pieces ";
  const std::size_t line = file.find(tag), end = file.find('\n', line);
  ASSERT_NE(line, std::string::npos);
  std::istringstream words(file.substr(line + tag.size(), end - line - tag.size()));
  std::size_t unpacked = 0, first = 0, second = 0, third = 0;
  ASSERT_TRUE(words >> unpacked >> first >> second >> third);
  ASSERT_NE(first, second);
  const std::string swapped = tag + std::to_string(unpacked) + " " + std::to_string(second) + " " +
                              std::to_string(first) + " " + std::to_string(third);
  const std::string short_of_one = tag + std::to_string(unpacked) + " " + std::to_string(first + second + third);
  // Sizes whose sum wraps around to the body's: the first would lie far beyond the file.
  const std::string wrapping = tag + std::to_string(unpacked) + " " +
                               std::to_string(std::numeric_limits<std::size_t>::max()) + " 1 " +
                               std::to_string(first + second + third);
  for (const std::string& lie : {swapped, short_of_one, wrapping}) {
    std::string damaged = file;
    damaged.replace(line, end - line, lie);
    std::ofstream(path, std::ios::binary) << damaged;
    pcl::PCLPointCloud2 blob;
    EXPECT_FALSE(readInPieces(path, blob)) << lie;
    msf::loadCloudBlob(path, blob); // PCL reads the one stream whole
    expectSameAsPclReads(blob, path);
    pcl::PointCloud<pcl::PointXYZRGBNormal> back;
    pcl::fromPCLPointCloud2(blob, back);
    EXPECT_EQ(back[69999].z, surfaceCloud(70000)[69999].z) << lie;
  }
}

TEST(CompressedPcd, DataShorterThanItsPointsIsRefused) {
  pcl::PCLPointCloud2 blob = surfaceBlob(100);
  blob.data.resize(blob.data.size() / 2);
  std::ostringstream out;
  try {
    msf::writeCompressedPcd(out, blob, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity());
    ADD_FAILURE() << "a cloud with half its data was written";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("not its 100 points"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(out.str().empty());
}

} // namespace

namespace {

TEST(CompressedPcd, MorePointsThanTheFormatHoldsAreRefusedByNameWithNoFile) {
  pcl::PCLPointCloud2 blob = surfaceBlob(1);
  blob.width = 1000000000; // a header's claim: 1e9 points, no data behind it
  msf::test::TempDir dir;
  try {
    msf::saveCloudBlob(dir.file("huge.pcd"), blob);
    ADD_FAILURE() << "a cloud beyond the format's 32-bit sizes was written";
  } catch (const msf::IOError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot write '" + dir.file("huge.pcd") + "': its 1000000000 points of"), std::string::npos)
        << what;
    EXPECT_NE(what.find("its sizes are 32-bit"), std::string::npos) << what;
  }
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u) << "a file or temporary was left";
}

} // namespace
