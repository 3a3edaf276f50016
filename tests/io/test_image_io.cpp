// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/depth_colormap.h>
#include <msf/io/image_io.h>
#include <msf/io/organized_conversion.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <limits>

namespace {

msf::Calibration smallCamera() {
  msf::Calibration c;
  c.image_size = cv::Size(40, 30);
  for (int i = 0; i < 4; ++i) {
    c.P[i] << 50, 0, 20, 0, 0, 50, 15, 0, 0, 0, 1, 0;
  }
  c.P[1](0, 3) = -50 * 0.5; // 0.5 m baseline
  c.source = "test camera";
  return c;
}

cv::Mat rampDepth() {
  cv::Mat depth(30, 40, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u)
      depth.at<float>(v, u) = ((u + v) % 7 == 0) ? 0.f : 2.f + 0.37f * u + 0.11f * v;
  return depth;
}

TEST(KittiPng, DepthRoundTripWithinQuantization) {
  msf::test::TempDir dir;
  const cv::Mat depth = rampDepth();
  msf::writeKittiDepthPng(dir.file("d.png"), depth);
  const cv::Mat back = msf::readKittiDepthPng(dir.file("d.png"));
  ASSERT_EQ(back.size(), depth.size());
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      EXPECT_NEAR(back.at<float>(v, u), depth.at<float>(v, u), 0.5 / 256 + 1e-6);
      EXPECT_EQ(back.at<float>(v, u) == 0.f, depth.at<float>(v, u) == 0.f);
    }
}

TEST(KittiPng, NanAndNegativeAreNoneAndLargeValuesClamp) {
  msf::test::TempDir dir;
  cv::Mat d(1, 4, CV_32FC1);
  d.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  d.at<float>(0, 1) = -3.f;
  d.at<float>(0, 2) = 1000.f;
  d.at<float>(0, 3) = 0.001f; // below one step: kept as the smallest positive value
  msf::writeKittiDisparityPng(dir.file("d.png"), d);
  const cv::Mat back = msf::readKittiDisparityPng(dir.file("d.png"));
  EXPECT_EQ(back.at<float>(0, 0), 0.f);
  EXPECT_EQ(back.at<float>(0, 1), 0.f);
  EXPECT_NEAR(back.at<float>(0, 2), 65535.0 / 256, 1e-4);
  EXPECT_NEAR(back.at<float>(0, 3), 1.0 / 256, 1e-6);
}

TEST(KittiPng, EightBitImageIsNotADepthPng) {
  msf::test::TempDir dir;
  msf::writeImage(dir.file("grey.png"), cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)));
  EXPECT_THROW(msf::readKittiDepthPng(dir.file("grey.png")), msf::IOError);
  EXPECT_THROW(msf::readImage(dir.file("missing.png")), msf::IOError);
  EXPECT_THROW(msf::writeImage("/nonexistent/x.png", cv::Mat(4, 4, CV_8UC1)), msf::IOError);
}

TEST(OrganizedConversion, DepthToCloudPutsEachPointOnItsRay) {
  const msf::Calibration c = smallCamera();
  const cv::Mat depth = rampDepth();
  pcl::PointCloud<pcl::PointXYZ> cloud;
  msf::depthImageToCloud(depth, c, 0, cloud);
  ASSERT_EQ(cloud.width, 40u);
  ASSERT_EQ(cloud.height, 30u);
  EXPECT_FALSE(cloud.is_dense);
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 40; ++u) {
      const auto& p = cloud.at(u, v);
      const float z = depth.at<float>(v, u);
      if (z == 0.f) {
        EXPECT_TRUE(std::isnan(p.z));
        continue;
      }
      // Reprojection lands on the pixel.
      EXPECT_NEAR(50 * p.x / p.z + 20, u, 1e-4);
      EXPECT_NEAR(50 * p.y / p.z + 15, v, 1e-4);
    }
  const cv::Mat back = msf::cloudToDepthImage(cloud);
  EXPECT_EQ(cv::norm(back, depth, cv::NORM_INF), 0.0);
}

TEST(OrganizedConversion, DisparityIsFocalBaselineOverDepth) {
  const msf::Calibration c = smallCamera();
  EXPECT_NEAR(c.baselineGrey(), 0.5, 1e-12);
  const cv::Mat depth = rampDepth();
  const cv::Mat disparity = msf::depthToDisparity(depth, c);
  EXPECT_NEAR(disparity.at<float>(3, 5), 25.0 / depth.at<float>(3, 5), 1e-5);
  EXPECT_EQ(disparity.at<float>(0, 0), 0.f);
  EXPECT_LT(cv::norm(msf::disparityToDepth(disparity, c), depth, cv::NORM_INF), 1e-4);
}

TEST(OrganizedConversion, RejectsUnorganizedAndMismatchedInput) {
  pcl::PointCloud<pcl::PointXYZ> line;
  line.resize(10);
  line.width = 10;
  line.height = 1;
  EXPECT_THROW(msf::cloudToDepthImage(line), msf::InvalidInputError);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  EXPECT_THROW(msf::depthImageToCloud(cv::Mat(31, 40, CV_32FC1, cv::Scalar(1)), smallCamera(), 0, cloud),
               msf::InvalidInputError);
  EXPECT_THROW(msf::depthImageToCloud(cv::Mat(30, 40, CV_8UC1), smallCamera(), 0, cloud), msf::InvalidInputError);
}

TEST(DepthColormap, NearIsWarmMissingIsBlackAndLegendIsAppended) {
  cv::Mat depth(10, 200, CV_32FC1, cv::Scalar(0));
  depth(cv::Rect(0, 0, 100, 10)).setTo(5.f);
  depth(cv::Rect(100, 0, 50, 10)).setTo(50.f);
  const cv::Mat picture = msf::colorizeDepth(depth, 5.f, 50.f, true);
  EXPECT_GT(picture.rows, 10);
  const cv::Vec3b near = picture.at<cv::Vec3b>(5, 10), far = picture.at<cv::Vec3b>(5, 120),
                  none = picture.at<cv::Vec3b>(5, 180);
  EXPECT_GT(near[2], near[0]); // red over blue
  EXPECT_GT(far[0], far[2]);   // blue over red
  EXPECT_EQ(none, cv::Vec3b(0, 0, 0));
}

} // namespace
