// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The foundation's tools, run as a user runs them.
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/velodyne_io.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <pcl/point_types.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace {

using msf::test::runTool;

std::string scanPath(int i) {
  char name[64];
  std::snprintf(name, sizeof name, "/odometry/sequences/04/velodyne/%06d.bin", i);
  return msf::test::kittiDir() + name;
}

void expectCleanFailure(const msf::test::CommandResult& r, const std::string& tool, const std::string& words) {
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(tool + ": error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
}

TEST(Kitti2Pcd, WritesEveryFiniteRecord) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const auto r = runTool("msf_kitti2pcd", scanPath(0) + " " + dir.file("out.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("[done, "), std::string::npos);
  pcl::PointCloud<pcl::PointXYZI> written, read;
  msf::loadCloud(dir.file("out.pcd"), written);
  const auto stats = msf::loadVelodyneBin(scanPath(0), read);
  EXPECT_EQ(written.size(), stats.records - stats.dropped_nonfinite);
  EXPECT_EQ(written.back().intensity, read.back().intensity);
}

TEST(Kitti2Pcd, TruncatedScanFailsWithoutOutput) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  std::ifstream in(scanPath(0), std::ios::binary);
  std::string bytes(1000, '\0');
  in.read(bytes.data(), 1000);
  std::ofstream(dir.file("cut.bin"), std::ios::binary) << bytes;
  const auto r = runTool("msf_kitti2pcd", dir.file("cut.bin") + " " + dir.file("out.pcd"));
  expectCleanFailure(r, "msf_kitti2pcd", dir.file("cut.bin"));
  EXPECT_NE(r.err.find("1000 bytes"), std::string::npos);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u); // only cut.bin
}

TEST(Kitti2Pcd, BatchMode) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir in, out;
  for (int i : {0, 1})
    std::filesystem::copy_file(scanPath(i), in.file(std::filesystem::path(scanPath(i)).filename().string()));
  const auto r = runTool("msf_kitti2pcd", "-input_dir " + in.path() + " -output_dir " + out.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(msf::test::fileExists(out.file("000000.pcd")));
  EXPECT_TRUE(msf::test::fileExists(out.file("000001.pcd")));
}

TEST(Kitti2Pcd, BadArguments) {
  msf::test::TempDir dir;
  expectCleanFailure(runTool("msf_kitti2pcd", "/nonexistent/a.bin " + dir.file("o.pcd")), "msf_kitti2pcd",
                     "does not exist");
  expectCleanFailure(runTool("msf_kitti2pcd", "a.bin o.pcd -voxel 3"), "msf_kitti2pcd", "unknown option '-voxel'");
  expectCleanFailure(runTool("msf_kitti2pcd", "-input_dir " + dir.path()), "msf_kitti2pcd", "-output_dir");
  EXPECT_EQ(runTool("msf_kitti2pcd", "-h").exit_code, 0);
}

TEST(Kitti2Pcd, UnwritableOutputFolder) {
  MSF_REQUIRE_KITTI();
  const auto r = runTool("msf_kitti2pcd", scanPath(0) + " /nonexistent_out/o.pcd");
  expectCleanFailure(r, "msf_kitti2pcd", "/nonexistent_out");
}

class Pcd2Png : public ::testing::Test {
protected:
  msf::test::TempDir dir;
  msf::Calibration calibration;
  cv::Mat depth;
  void SetUp() override {
    calibration.image_size = cv::Size(64, 48);
    for (auto& P : calibration.P)
      P << 60, 0, 32, 0, 0, 60, 24, 0, 0, 0, 1, 0;
    calibration.P[1](0, 3) = -60 * 0.5;
    msf::saveCalibrationYaml(calibration, dir.file("camera.yaml"));
    depth = cv::Mat(48, 64, CV_32FC1, cv::Scalar(0));
    for (int v = 10; v < 48; ++v)
      for (int u = 0; u < 64; ++u)
        depth.at<float>(v, u) = 3.f + 0.25f * u;
    pcl::PointCloud<pcl::PointXYZ> cloud;
    msf::depthImageToCloud(depth, calibration, 0, cloud);
    msf::saveCloud(dir.file("depth.pcd"), cloud);
  }
};

TEST_F(Pcd2Png, DepthPngRoundTrip) {
  const auto r = runTool("msf_pcd2png", dir.file("depth.pcd") + " " + dir.file("d.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(cv::norm(msf::readKittiDepthPng(dir.file("d.png")), depth, cv::NORM_INF), 0.5 / 256 + 1e-6);
}

TEST_F(Pcd2Png, DisparityNeedsCalibration) {
  expectCleanFailure(runTool("msf_pcd2png", dir.file("depth.pcd") + " " + dir.file("d.png") + " -disparity"),
                     "msf_pcd2png", "-calib");
  const auto r = runTool("msf_pcd2png",
                         dir.file("depth.pcd") + " " + dir.file("d.png") + " -disparity -calib " + dir.file("camera.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat disparity = msf::readKittiDisparityPng(dir.file("d.png"));
  EXPECT_NEAR(disparity.at<float>(20, 8), 30.0 / 5.0, 1.0 / 256);
  EXPECT_EQ(disparity.at<float>(5, 8), 0.f);
}

TEST_F(Pcd2Png, ColourPictureWithLegend) {
  const auto r = runTool("msf_pcd2png", dir.file("depth.pcd") + " " + dir.file("c.png") + " -color");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat picture = msf::readImage(dir.file("c.png"));
  EXPECT_EQ(picture.type(), CV_8UC3);
  EXPECT_EQ(picture.cols, 64);
  EXPECT_GT(picture.rows, 48); // legend below
}

TEST_F(Pcd2Png, UnorganizedCloudIsRejected) {
  MSF_REQUIRE_KITTI();
  ASSERT_EQ(runTool("msf_kitti2pcd", scanPath(0) + " " + dir.file("scan.pcd")).exit_code, 0);
  const auto r = runTool("msf_pcd2png", dir.file("scan.pcd") + " " + dir.file("x.png"));
  expectCleanFailure(r, "msf_pcd2png", "not organized");
  EXPECT_FALSE(msf::test::fileExists(dir.file("x.png")));
}

TEST_F(Pcd2Png, InfoDescribesTheCloud) {
  const auto r = runTool("msf_info", dir.file("depth.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("organized:  yes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("64 x 48"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("valid:      2432"), std::string::npos) << r.out; // 38 rows x 64
  EXPECT_NE(r.out.find("depth z:    3.000 .. 18.750 m"), std::string::npos) << r.out;
  expectCleanFailure(runTool("msf_info", dir.file("missing.pcd")), "msf_info", "does not exist");
}

} // namespace
