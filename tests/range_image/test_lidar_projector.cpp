// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper step 1 on hand-placed points with known pixels, and on a real KITTI scan.
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/point_types.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <thread>
#include <vector>

namespace {

pcl::PointXYZI velo(float forward, float left, float up, float reflectance) {
  pcl::PointXYZI p;
  p.x = forward;
  p.y = left;
  p.z = up;
  p.intensity = reflectance;
  return p;
}

/// A velodyne point that lands on pixel (u, v) at depth z in smallCamera().
pcl::PointXYZI atPixel(float u, float v, float z, float reflectance = 0.5f) {
  return velo(z, -(u - 50.f) * z / 100.f, -(v - 40.f) * z / 100.f, reflectance);
}

TEST(LidarProjector, PointsLandOnTheirPixelsAndTheNearestWins) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  scan.push_back(atPixel(50, 40, 10.f, 0.1f));
  scan.push_back(atPixel(50, 40, 5.f, 0.2f));   // same pixel, nearer: wins
  scan.push_back(atPixel(50, 40, 7.f, 0.3f));
  scan.push_back(atPixel(10.3f, 70.4f, 3.f, 0.4f)); // rounds to (10, 70)
  scan.push_back(velo(-10.f, 0.f, 0.f, 0.9f));      // behind the camera
  scan.push_back(atPixel(120, 40, 10.f));           // right of the image
  scan.push_back(atPixel(50, -1, 10.f));            // above it
  const msf::LidarProjector projector(msf::test::smallCalibration());
  pcl::PointCloud<msf::PointXYZID> cloud;
  projector.project(scan, cloud);
  ASSERT_EQ(cloud.width, 100u);
  ASSERT_EQ(cloud.height, 80u);
  EXPECT_FALSE(cloud.is_dense);
  std::size_t valid = 0;
  for (const auto& p : cloud)
    valid += std::isfinite(p.z);
  EXPECT_EQ(valid, 2u);
  EXPECT_NEAR(cloud(50, 40).z, 5.f, 1e-5f);
  EXPECT_EQ(cloud(50, 40).intensity, 0.2f);
  EXPECT_EQ(cloud(50, 40).distance, 0.f);
  EXPECT_NEAR(cloud(10, 70).z, 3.f, 1e-5f);
  // The exact point is kept: within half a pixel of the ray of its pixel.
  EXPECT_NEAR(100.f * cloud(10, 70).x / cloud(10, 70).z + 50.f, 10.3f, 1e-4f);
  EXPECT_TRUE(std::isinf(cloud(0, 0).distance));

  cv::Mat depth, intensity;
  projector.projectToImage(scan, depth, &intensity);
  EXPECT_NEAR(depth.at<float>(40, 50), 5.f, 1e-5f);
  EXPECT_EQ(intensity.at<float>(40, 50), 0.2f);
  EXPECT_EQ(cv::countNonZero(depth), 2);
}

TEST(LidarProjector, RangeLimitsAreDistancesFromTheLidar) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  scan.push_back(atPixel(50, 40, 1.f));
  scan.push_back(atPixel(20, 40, 50.f));
  scan.push_back(atPixel(80, 40, 20.f));
  msf::ProjectionConfig config;
  config.min_range_m = 2.f;
  config.max_range_m = 40.f;
  const msf::LidarProjector projector(msf::test::smallCalibration(), config);
  cv::Mat depth;
  projector.projectToImage(scan, depth);
  EXPECT_EQ(depth.at<float>(40, 50), 0.f);
  EXPECT_EQ(depth.at<float>(40, 20), 0.f);
  EXPECT_GT(depth.at<float>(40, 80), 0.f);
}

TEST(LidarProjector, OtherCamerasUseTheirOwnFrame) {
  // Camera 1 sits 0.5 m to the right of camera 0: the same point is 0.5 m further left in it.
  pcl::PointCloud<pcl::PointXYZI> scan;
  scan.push_back(atPixel(50, 40, 10.f));
  msf::ProjectionConfig config;
  config.camera = 1;
  const msf::LidarProjector projector(msf::test::smallCalibration(), config);
  pcl::PointCloud<pcl::PointXYZI> cloud;
  projector.project(scan, cloud);
  // u = fx (x - B) / z + cx = 100 * (0 - 0.5) / 10 + 50 = 45
  ASSERT_TRUE(std::isfinite(cloud(45, 40).z));
  EXPECT_NEAR(cloud(45, 40).x, -0.5f, 1e-5f);
}

TEST(LidarProjector, TheCanvasKeepsReturnsJustOutsideTheImage) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  scan.push_back(atPixel(-3, 40, 10.f));  // 3 px left of the image
  scan.push_back(atPixel(50, 84, 10.f));  // 4 px below it
  scan.push_back(atPixel(50, 40, 10.f));
  msf::ProjectionConfig config;
  config.margin_px = 5;
  const msf::LidarProjector projector(msf::test::smallCalibration(), config);
  cv::Mat canvas, image;
  projector.projectToCanvas(scan, canvas);
  projector.projectToImage(scan, image);
  ASSERT_EQ(canvas.size(), cv::Size(110, 90));
  EXPECT_EQ(projector.imageInCanvas(), cv::Rect(5, 5, 100, 80));
  EXPECT_GT(canvas.at<float>(45, 2), 0.f);
  EXPECT_GT(canvas.at<float>(89, 55), 0.f);
  EXPECT_GT(canvas.at<float>(45, 55), 0.f);
  EXPECT_EQ(cv::countNonZero(image), 1);
  const msf::PinholeCamera c = projector.canvasCamera();
  EXPECT_EQ(c.cx, 55.f);
  EXPECT_EQ(c.width, 110);
}

TEST(LidarProjector, BadConfigsAndMissingCalibration) {
  msf::ProjectionConfig config;
  config.max_range_m = -1.f;
  EXPECT_THROW(msf::LidarProjector(msf::test::smallCalibration(), config), msf::ConfigError);
  config = msf::ProjectionConfig();
  config.camera = 4;
  try {
    config.validate();
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("projection.camera"), std::string::npos);
  }
  msf::Calibration no_size = msf::test::smallCalibration();
  no_size.image_size = cv::Size(0, 0);
  EXPECT_THROW(msf::LidarProjector{no_size}, msf::CalibrationError);
  cv::Mat depth;
  EXPECT_THROW(msf::LidarProjector().projectToImage(pcl::PointCloud<pcl::PointXYZI>(), depth), msf::InvalidInputError);
}

TEST(LidarProjector, OneProjectorServesSeveralThreadsAtOnce) {
  // Two threads project two different KITTI scans through one const projector, many times
  // over: each gets exactly what a projection alone gives.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  pcl::PointCloud<pcl::PointXYZI> scans[2];
  msf::loadVelodyneBin(sequence.scanPath(0), scans[0]);
  msf::loadVelodyneBin(sequence.scanPath(5), scans[1]);
  const msf::LidarProjector projector(sequence.calibration());
  cv::Mat expected_depth[2], expected_intensity[2];
  pcl::PointCloud<msf::PointXYZID> expected_cloud[2];
  for (int k = 0; k < 2; ++k) {
    projector.projectToCanvas(scans[k], expected_depth[k], &expected_intensity[k]);
    projector.project(scans[k], expected_cloud[k]);
  }
  ASSERT_GT(cv::norm(expected_depth[0], expected_depth[1], cv::NORM_INF), 0.0); // the scans differ
  std::vector<int> mismatches(2, 0);
  auto work = [&](int k) {
    for (int round = 0; round < 20; ++round) {
      cv::Mat depth, intensity;
      pcl::PointCloud<msf::PointXYZID> cloud;
      projector.projectToCanvas(scans[k], depth, &intensity);
      projector.project(scans[k], cloud);
      bool same = cv::norm(depth, expected_depth[k], cv::NORM_INF) == 0.0 &&
                  cv::norm(intensity, expected_intensity[k], cv::NORM_INF) == 0.0 &&
                  cloud.size() == expected_cloud[k].size();
      for (std::size_t i = 0; same && i < cloud.size(); ++i)
        same = std::isfinite(cloud[i].z) ? cloud[i].z == expected_cloud[k][i].z
                                         : !std::isfinite(expected_cloud[k][i].z);
      mismatches[k] += !same;
    }
  };
  std::thread other(work, 1);
  work(0);
  other.join();
  EXPECT_EQ(mismatches[0], 0);
  EXPECT_EQ(mismatches[1], 0);
}

TEST(LidarProjector, RealKittiScan) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  pcl::PointCloud<pcl::PointXYZI> scan;
  msf::loadVelodyneBin(sequence.scanPath(0), scan);
  const msf::LidarProjector projector(sequence.calibration());
  pcl::PointCloud<msf::PointXYZID> cloud;
  projector.project(scan, cloud);
  ASSERT_EQ(cloud.width, 1226u);
  ASSERT_EQ(cloud.height, 370u);
  const msf::PinholeCamera& cam = projector.camera();
  std::size_t returns = 0;
  for (std::uint32_t v = 0; v < cloud.height; ++v)
    for (std::uint32_t u = 0; u < cloud.width; ++u) {
      const auto& p = cloud(u, v);
      if (!std::isfinite(p.z))
        continue;
      ++returns;
      ASSERT_GT(p.z, 0.f);
      ASSERT_LE(std::abs(cam.fx * p.x / p.z + cam.cx - static_cast<float>(u)), 0.5f + 1e-3f);
      ASSERT_LE(std::abs(cam.fy * p.y / p.z + cam.cy - static_cast<float>(v)), 0.5f + 1e-3f);
    }
  // A few percent of the pixels, about a sixth of the scan (the camera's field of view).
  EXPECT_GT(returns, 15000u);
  EXPECT_LT(returns, 30000u);
}

} // namespace
