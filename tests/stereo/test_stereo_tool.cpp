// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/range_image/point_types.h>
#include <msf/stereo/point_types.h>

#include "stereo_scenes.h"
#include "test_support.h"

#include <opencv2/imgcodecs.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <fstream>

namespace {

const cv::Size kSize(320, 160);

struct Scene {
  msf::test::TempDir dir;
  std::string left = dir.file("left.png"), right = dir.file("right.png"), calib = dir.file("calib.yaml"),
              out = dir.file("stereo.pcd"), disparity = dir.file("disparity.png");
  msf::test::SyntheticPair pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  Scene() {
    cv::imwrite(left, pair.left);
    cv::imwrite(right, pair.right);
    msf::saveCalibrationYaml(msf::test::syntheticCalibration(kSize, 500.0, 0.5), calib);
  }
  std::string args(const std::string& extra = "") const {
    return left + " " + right + " " + out + " -calib " + calib + " -num_disparities 48 " + extra;
  }
};

TEST(StereoTool, WritesTheOrganizedCloudAndTheDisparityPng) {
  Scene s;
  const auto r = msf::test::runTool("msf_stereo", s.args("-disparity_png " + s.disparity));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(48 disparities)"), std::string::npos) << r.out;
  pcl::PointCloud<msf::PointXYZRGBConfidence> cloud;
  msf::loadCloud(s.out, cloud); // fails unless the file has x y z rgb confidence
  ASSERT_EQ(cloud.width, static_cast<std::uint32_t>(kSize.width));
  ASSERT_EQ(cloud.height, static_cast<std::uint32_t>(kSize.height));
  EXPECT_NEAR(cloud.at(100, 80).z, 250.f / 12.f, 0.2f);
  EXPECT_NEAR(cloud.at(200, 80).z, 250.f / 30.f, 0.05f);
  EXPECT_GT(cloud.at(100, 80).confidence, 0.9f);
  EXPECT_EQ(cloud.at(100, 80).r, s.pair.left.at<std::uint8_t>(80, 100)); // grey without -color
  const cv::Mat d = msf::readKittiDisparityPng(s.disparity);
  EXPECT_NEAR(d.at<float>(80, 100), 12.f, 0.1f);
  EXPECT_NEAR(d.at<float>(80, 200), 30.f, 0.1f);
}

TEST(StereoTool, ConfigSectionAndOverrides) {
  Scene s;
  const std::string config = s.dir.file("c.yaml");
  std::ofstream(config) << "%YAML:1.0\nstereo:\n  num_disparities_px: 64\n  block_size_px: 7\n";
  auto r = msf::test::runTool("msf_stereo", s.left + " " + s.right + " " + s.out + " -calib " + s.calib + " -config " +
                                                config + " -print_config");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("block_size_px: 7"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(64 disparities)"), std::string::npos) << r.out;
  // A flag overrides the file.
  r = msf::test::runTool("msf_stereo", s.left + " " + s.right + " " + s.out + " -calib " + s.calib + " -config " +
                                           config + " -num_disparities 32 -overwrite");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(32 disparities)"), std::string::npos) << r.out;
}

TEST(StereoTool, APriorGuidesThroughItsRealReturnsOnly) {
  Scene s;
  // The prior of msf_interpolate: organized, with `distance` 0 on the real returns.
  pcl::PointCloud<msf::PointXYZID> with_distance(kSize.width, kSize.height);
  pcl::PointCloud<pcl::PointXYZ> without(kSize.width, kSize.height);
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < kSize.width; ++u) {
      const float z = 250.f / 12.f;
      with_distance.at(u, v) = msf::PointXYZID(0.f, 0.f, z, 0.f, v % 4 == 0 ? 0.f : 1.f);
      without.at(u, v) = pcl::PointXYZ(0.f, 0.f, z);
    }
  const std::string guided = s.dir.file("lidar.pcd"), plain = s.dir.file("xyz.pcd");
  msf::saveCloud(guided, with_distance);
  msf::saveCloud(plain, without);
  auto r = msf::test::runTool("msf_stereo", s.args("-prior " + guided));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("distance"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_stereo", s.args("-prior " + plain + " -overwrite"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("has no field 'distance'"), std::string::npos) << r.err;
  EXPECT_TRUE(msf::test::fileExists(s.out));
}

TEST(StereoTool, BadInputFailsAndLeavesNoOutput) {
  Scene s;
  const auto fails = [&](const std::string& args, const std::string& message) {
    const auto r = msf::test::runTool("msf_stereo", args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_NE(r.err.find("msf_stereo: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << "expected '" << message << "' in: " << r.err;
    EXPECT_FALSE(msf::test::fileExists(s.out));
    EXPECT_FALSE(msf::test::fileExists(s.disparity));
  };
  // A missing image.
  fails(s.dir.file("none.png") + " " + s.right + " " + s.out + " -calib " + s.calib, "none.png");
  // Images whose size does not match the calibration.
  const std::string big_calib = s.dir.file("big.yaml");
  msf::saveCalibrationYaml(msf::test::syntheticCalibration(cv::Size(1226, 370)), big_calib);
  fails(s.left + " " + s.right + " " + s.out + " -calib " + big_calib + " -disparity_png " + s.disparity,
        "320x160 but calibration");
  // Left and right of different sizes.
  const std::string small = s.dir.file("small.png");
  cv::imwrite(small, s.pair.right(cv::Rect(0, 0, 300, 160)));
  fails(s.left + " " + small + " " + s.out + " -calib " + s.calib, "but the right image is 300x160");
  // Bad settings, a bad output name, an unknown option, no calibration.
  fails(s.left + " " + s.right + " " + s.out + " -calib " + s.calib + " -num_disparities 50", "stereo.num_disparities_px");
  fails(s.args("-mode fast"), "stereo.mode");
  fails(s.left + " " + s.right + " " + s.dir.file("stereo.txt") + " -calib " + s.calib, "must end in .pcd or .ply");
  fails(s.args("-disparity_png " + s.dir.file("d.jpg")), "must end in .png");
  fails(s.args("-lr-check"), "unknown option '-lr-check'");
  fails(s.left + " " + s.right + " " + s.out, "-calib PATH is required");
  // An output folder that does not exist.
  fails(s.left + " " + s.right + " " + s.dir.file("no/dir/out.pcd") + " -calib " + s.calib, "does not exist");
  // Nothing but the inputs is left in the folder: left, right, calib, big calib, small.
  EXPECT_EQ(msf::test::countEntries(s.dir.path()), 5u);
}

TEST(StereoToolKitti, OdometryFrameWithColour) {
  MSF_REQUIRE_KITTI();
  const std::string seq = msf::test::kittiDir() + "/odometry/sequences/04/";
  msf::test::TempDir dir;
  const auto r = msf::test::runTool("msf_stereo", seq + "image_0/000000.png " + seq + "image_1/000000.png " +
                                                      dir.file("s.pcd") + " -calib " + seq + "calib.txt -color " + seq +
                                                      "image_2/000000.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<msf::PointXYZRGBConfidence> cloud;
  msf::loadCloud(dir.file("s.pcd"), cloud);
  ASSERT_EQ(cloud.width, 1226u);
  ASSERT_EQ(cloud.height, 370u);
  std::size_t valid = 0, coloured = 0;
  for (const auto& p : cloud) {
    if (!std::isfinite(p.z))
      continue;
    ++valid;
    coloured += !(p.r == p.g && p.g == p.b); // image_2 is in colour
  }
  EXPECT_GT(valid, 0.8 * cloud.size()); // 128 disparities: the first 128 columns have no match
  EXPECT_GT(coloured, valid / 2);

  // A KITTI stereo benchmark's calibration (P0..P3, no Tr) is all the matching needs.
  std::ifstream in(seq + "calib.txt");
  std::string line, cameras;
  for (int n = 0; n < 4 && std::getline(in, line); ++n)
    cameras += line + "\n";
  std::ofstream(dir.file("cameras.txt")) << cameras;
  const auto p = msf::test::runTool("msf_stereo", seq + "image_0/000000.png " + seq + "image_1/000000.png " +
                                                      dir.file("p.pcd") + " -calib " + dir.file("cameras.txt"));
  ASSERT_EQ(p.exit_code, 0) << p.err;
  pcl::PointCloud<msf::PointXYZRGBConfidence> same;
  msf::loadCloud(dir.file("p.pcd"), same);
  ASSERT_EQ(same.size(), cloud.size());
  for (std::size_t i = 0; i < same.size(); i += 97)
    ASSERT_TRUE(std::isnan(same[i].z) ? std::isnan(cloud[i].z) : same[i].z == cloud[i].z) << i;
}

} // namespace
