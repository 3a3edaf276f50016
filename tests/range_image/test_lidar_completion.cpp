// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Steps 1 and 2 from a scan: the image path and the cloud path agree; the canvas helps.
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/lidar_completion.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>

namespace {

TEST(LidarCompletion, MethodNames) {
  EXPECT_EQ(msf::parseCompletionMethod("compound"), msf::CompletionMethod::Compound);
  EXPECT_EQ(msf::parseCompletionMethod("interpolated"), msf::CompletionMethod::Compound);
  EXPECT_EQ(msf::parseCompletionMethod("ipbasic_multiscale"), msf::CompletionMethod::IpBasicMultiscale);
  for (const auto m : {msf::CompletionMethod::Compound, msf::CompletionMethod::Linear, msf::CompletionMethod::Cubic,
                       msf::CompletionMethod::IpBasicFast, msf::CompletionMethod::IpBasicMultiscale})
    EXPECT_EQ(msf::parseCompletionMethod(msf::toString(m)), m);
  try {
    msf::parseCompletionMethod("sgbm");
    FAIL();
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("sgbm"), std::string::npos);
  }
}

class LidarCompletionKitti : public ::testing::Test {
protected:
  void SetUp() override {
    if (msf::test::kittiDir().empty())
      return;
    sequence_ = std::make_unique<msf::Sequence>(msf::test::kittiDir() + "/odometry/sequences/04");
    msf::loadVelodyneBin(sequence_->scanPath(0), scan_);
  }
  std::unique_ptr<msf::Sequence> sequence_;
  pcl::PointCloud<pcl::PointXYZI> scan_;
};

TEST_F(LidarCompletionKitti, ImageAndCloudPathsAgree) {
  MSF_REQUIRE_KITTI();
  for (const auto method : {msf::CompletionMethod::Compound, msf::CompletionMethod::IpBasicFast}) {
    msf::LidarCompletion completion(sequence_->calibration(), method);
    cv::Mat depth, distance;
    completion.computeDepth(scan_, depth, &distance);
    pcl::PointCloud<msf::PointXYZID> cloud;
    completion.compute(scan_, cloud);
    ASSERT_EQ(depth.size(), cv::Size(1226, 370));
    ASSERT_EQ(cloud.width, 1226u);
    ASSERT_EQ(cloud.height, 370u);
    std::size_t estimates = 0;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u) {
        const auto& p = cloud(static_cast<std::uint32_t>(u), static_cast<std::uint32_t>(v));
        const float z = depth.at<float>(v, u);
        ASSERT_EQ(std::isfinite(p.z), z > 0.f) << msf::toString(method) << " " << u << "," << v;
        if (z > 0.f) {
          ++estimates;
          ASSERT_NEAR(p.z, z, 1e-4f * z);
        }
        ASSERT_FLOAT_EQ(p.distance, distance.at<float>(v, u));
      }
    EXPECT_GT(estimates, 200000u) << msf::toString(method);
  }
}

TEST_F(LidarCompletionKitti, TheMarginBridgesTheBottomRows) {
  MSF_REQUIRE_KITTI();
  msf::ProjectionConfig with, without;
  without.margin_px = 0;
  cv::Mat a, b;
  msf::LidarCompletion(sequence_->calibration(), msf::CompletionMethod::Compound, with).computeDepth(scan_, a);
  msf::LidarCompletion(sequence_->calibration(), msf::CompletionMethod::Compound, without).computeDepth(scan_, b);
  const cv::Rect bottom(0, 355, 1226, 15);
  EXPECT_GT(cv::countNonZero(a(bottom)), cv::countNonZero(b(bottom)) + 1000);
  EXPECT_GT(cv::countNonZero(a(bottom)), 0.99 * bottom.area());
}

TEST(LidarCompletionSynthetic, TheGroundBetweenRingsIsThePlane) {
  // A flat ground 1.5 m below smallCamera(), scanned by rings that cross rows 43, 48, ...,
  // 78 (and two below the image, for the canvas) with a return every other column. Its
  // inverse depth is affine in the image, so linear slices are exact between the rings.
  // (With f = 100 px the ground's inverse depth changes by 0.033 / m across a 5-row gap:
  // above KITTI's default edge threshold, which is set for f = 707 px.)
  const msf::Calibration calibration = msf::test::smallCalibration();
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (int v = 43; v <= 88; v += 5)
    for (int u = v % 2; u < 100; u += 2) {
      const float z = 150.f / static_cast<float>(v - 40);
      pcl::PointXYZI p; // velodyne: forward = z, left = -x, up = -y
      p.x = z;
      p.y = -(static_cast<float>(u) - 50.f) * z / 100.f;
      p.z = -1.5f;
      p.intensity = 0.f;
      scan.push_back(p);
    }
  msf::InterpolationConfig interpolation;
  interpolation.slice.jump_inv_per_m = 0.1f;
  msf::LidarCompletion completion(calibration, msf::CompletionMethod::Linear, msf::ProjectionConfig(), interpolation);
  cv::Mat depth;
  completion.computeDepth(scan, depth);
  int checked = 0;
  for (int v = 43; v < 80; ++v)
    for (int u = 1; u < 99; ++u) {
      const float truth = 150.f / (static_cast<float>(v) - 40.f);
      ASSERT_GT(depth.at<float>(v, u), 0.f) << u << "," << v;
      EXPECT_NEAR(depth.at<float>(v, u), truth, 1e-4f * truth) << u << "," << v;
      ++checked;
    }
  EXPECT_EQ(checked, 37 * 98);
  EXPECT_EQ(depth.at<float>(20, 50), 0.f); // the sky stays empty
}

} // namespace
