// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The pcl::Filter on organized clouds: invariants, rays, distance, camera, errors.
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/io/organized_conversion.h>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/ip_basic_completion.h>
#include <msf/range_image/point_types.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <limits>

namespace {

using Cloud = pcl::PointCloud<msf::PointXYZID>;

/// The sparse scene as an organized cloud: points on their pixels' rays, intensity = u.
Cloud::Ptr sparseCloud() {
  const msf::PinholeCamera cam = msf::test::smallCamera();
  const cv::Mat depth = msf::test::sparseScene();
  Cloud::Ptr cloud(new Cloud(cam.width, cam.height));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      msf::PointXYZID& p = (*cloud)(u, v);
      const float z = depth.at<float>(v, u);
      if (z > 0.f) {
        p = msf::PointXYZID((u - cam.cx) * z / cam.fx, (v - cam.cy) * z / cam.fy, z, static_cast<float>(u), 0.f);
      } else {
        p = msf::PointXYZID(nan, nan, nan, 0.f, std::numeric_limits<float>::infinity());
      }
    }
  cloud->is_dense = false;
  return cloud;
}

TEST(CompoundInterpolation, OrganizedInvariantsAndRealReturnsKept) {
  const Cloud::Ptr sparse = sparseCloud();
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setCamera(msf::test::smallCamera());
  filter.setInputCloud(sparse);
  Cloud dense;
  filter.filter(dense);
  ASSERT_EQ(dense.width, sparse->width);
  ASSERT_EQ(dense.height, sparse->height);
  const cv::Mat& depth = filter.denseDepth();
  std::size_t nan_points = 0;
  for (std::uint32_t v = 0; v < dense.height; ++v)
    for (std::uint32_t u = 0; u < dense.width; ++u) {
      const msf::PointXYZID& p = dense(u, v);
      const msf::PointXYZID& s = (*sparse)(u, v);
      // NaN exactly where the completed depth has no estimate.
      EXPECT_EQ(std::isfinite(p.z), depth.at<float>(v, u) > 0.f) << u << "," << v;
      nan_points += !std::isfinite(p.z);
      if (std::isfinite(s.z)) {
        EXPECT_EQ(p.x, s.x);
        EXPECT_EQ(p.y, s.y);
        EXPECT_EQ(p.z, s.z);
        EXPECT_EQ(p.intensity, s.intensity);
        EXPECT_EQ(p.distance, 0.f);
      }
    }
  EXPECT_GT(nan_points, 0u); // the sky above the top ring
  EXPECT_FALSE(dense.is_dense);
}

TEST(CompoundInterpolation, NewPointsLieOnTheirPixelsRays) {
  const msf::PinholeCamera cam = msf::test::smallCamera();
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setCamera(cam);
  filter.setInputCloud(sparseCloud());
  Cloud dense;
  filter.filter(dense);
  int checked = 0;
  for (std::uint32_t v = 0; v < dense.height; ++v)
    for (std::uint32_t u = 0; u < dense.width; ++u) {
      const msf::PointXYZID& p = dense(u, v);
      if (!std::isfinite(p.z) || p.distance == 0.f)
        continue;
      EXPECT_NEAR(cam.fx * p.x / p.z + cam.cx, static_cast<float>(u), 1e-3f);
      EXPECT_NEAR(cam.fy * p.y / p.z + cam.cy, static_cast<float>(v), 1e-3f);
      ++checked;
    }
  EXPECT_GT(checked, 3000);
}

TEST(CompoundInterpolation, DistanceAndIntensityComeFromTheNearestRealReturn) {
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setCamera(msf::test::smallCamera());
  const Cloud::Ptr sparse = sparseCloud();
  filter.setInputCloud(sparse);
  Cloud dense;
  filter.filter(dense);
  for (std::uint32_t v = 0; v < dense.height; v += 3)
    for (std::uint32_t u = 0; u < dense.width; u += 3) {
      double best = std::numeric_limits<double>::infinity();
      for (std::uint32_t sv = 0; sv < sparse->height; ++sv)
        for (std::uint32_t su = 0; su < sparse->width; ++su)
          if (std::isfinite((*sparse)(su, sv).z))
            best = std::min(best, std::hypot(double(su) - u, double(sv) - v));
      EXPECT_NEAR(dense(u, v).distance, best, 1e-4) << u << "," << v;
      if (std::isfinite(dense(u, v).z)) {
        // intensity = column of the nearest return, within the distance
        EXPECT_LE(std::abs(dense(u, v).intensity - static_cast<float>(u)), best + 1e-3) << u << "," << v;
      }
    }
}

TEST(CompoundInterpolation, RecoversTheCameraFromTheCloud) {
  msf::CompoundInterpolation<msf::PointXYZID> with, without;
  with.setCamera(msf::test::smallCamera());
  const Cloud::Ptr sparse = sparseCloud();
  with.setInputCloud(sparse);
  without.setInputCloud(sparse);
  Cloud a, b;
  with.filter(a);
  without.filter(b);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::isfinite(a[i].z), std::isfinite(b[i].z));
    if (std::isfinite(a[i].z)) {
      EXPECT_NEAR(a[i].x, b[i].x, 1e-3f * a[i].z);
      EXPECT_NEAR(a[i].y, b[i].y, 1e-3f * a[i].z);
      EXPECT_FLOAT_EQ(a[i].z, b[i].z);
    }
  }
}

TEST(CompoundInterpolation, AnUnorganizedCloudIsAClearError) {
  Cloud::Ptr scan(new Cloud);
  for (int i = 0; i < 100; ++i)
    scan->push_back(msf::PointXYZID(1.f * i, 0.f, 5.f));
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setInputCloud(scan);
  Cloud out;
  try {
    filter.filter(out);
    FAIL() << "an unorganized cloud was accepted";
  } catch (const msf::InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("CompoundInterpolation"), std::string::npos) << what;
    EXPECT_NE(what.find("organized"), std::string::npos) << what;
    EXPECT_NE(what.find("100x1"), std::string::npos) << what;
  }
}

TEST(CompoundInterpolation, ACameraOfAnotherSizeIsAnError) {
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  msf::PinholeCamera cam = msf::test::smallCamera();
  cam.width = 120;
  filter.setCamera(cam);
  filter.setInputCloud(sparseCloud());
  Cloud out;
  EXPECT_THROW(filter.filter(out), msf::InvalidInputError);
}

TEST(CompoundInterpolation, SetIndicesChoosesTheReturnsCompletedFrom) {
  // The left half's points as indices complete as the cloud whose right half has no returns;
  // the output is still the whole organized cloud.
  const Cloud::Ptr sparse = sparseCloud();
  const int W = static_cast<int>(sparse->width);
  pcl::IndicesPtr left(new pcl::Indices);
  Cloud::Ptr left_only(new Cloud(*sparse));
  for (std::size_t i = 0; i < sparse->size(); ++i) {
    if (static_cast<int>(i) % W < W / 2)
      left->push_back(static_cast<pcl::index_t>(i));
    else
      (*left_only)[i].z = std::numeric_limits<float>::quiet_NaN();
  }
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setCamera(msf::test::smallCamera());
  filter.setInputCloud(left_only);
  Cloud expected;
  filter.filter(expected);
  const cv::Mat expected_depth = filter.denseDepth().clone();
  filter.setInputCloud(sparse);
  filter.setIndices(left);
  Cloud out;
  filter.filter(out);
  ASSERT_EQ(out.width, sparse->width);
  ASSERT_EQ(out.height, sparse->height);
  EXPECT_EQ(cv::norm(filter.denseDepth(), expected_depth, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::countNonZero(expected_depth.colRange(W / 2, W)), 0); // completed over the right half too
  left->push_back(static_cast<pcl::index_t>(sparse->size()));
  EXPECT_THROW(filter.filter(out), msf::InvalidInputError);
}

TEST(CompoundInterpolation, ACloudOffItsRaysCannotRecoverACamera) {
  Cloud::Ptr cloud = sparseCloud();
  cv::RNG rng(1);
  for (auto& p : *cloud)
    if (std::isfinite(p.z))
      p.x += static_cast<float>(rng.uniform(-3.0, 3.0)); // metres: far off the rays
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setInputCloud(cloud);
  Cloud out;
  EXPECT_THROW(filter.filter(out), msf::InvalidInputError);
}

TEST(CompoundInterpolation, SettersReachTheConfigAndAreValidated) {
  msf::CompoundInterpolation<pcl::PointXYZ> filter;
  filter.setShortGap(2);
  filter.setMaxGap(9);
  filter.setInterpolant(msf::SliceInterpolant::Cubic);
  filter.setCombineRule(msf::CombineRule::Average);
  filter.setGaussianFill(false);
  filter.setNumberOfThreads(1);
  EXPECT_EQ(filter.getShortGap(), 2);
  EXPECT_EQ(filter.getMaxGap(), 9);
  EXPECT_EQ(filter.getInterpolant(), msf::SliceInterpolant::Cubic);
  EXPECT_EQ(filter.getCombineRule(), msf::CombineRule::Average);
  EXPECT_FALSE(filter.getGaussianFill());
  EXPECT_EQ(filter.getNumberOfThreads(), 1);
  filter.setMaxGap(1); // below short_gap: rejected when the filter runs
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  msf::depthImageToCloud(msf::test::sparseScene(), msf::test::smallCalibration(), 0, *cloud);
  filter.setInputCloud(cloud);
  pcl::PointCloud<pcl::PointXYZ> out;
  EXPECT_THROW(filter.filter(out), msf::ConfigError);
}

TEST(CompoundInterpolation, OtherPointTypesAndInPlace) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  msf::depthImageToCloud(msf::test::sparseScene(), msf::test::smallCalibration(), 0, *cloud);
  msf::CompoundInterpolation<pcl::PointXYZ> filter;
  filter.setInputCloud(cloud);
  pcl::PointCloud<pcl::PointXYZ> out;
  filter.filter(out);
  filter.filter(*cloud); // output = input: PCL filters through a temporary
  ASSERT_EQ(out.size(), cloud->size());
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_TRUE(std::isfinite(out[i].z) ? out[i].z == (*cloud)[i].z : !std::isfinite((*cloud)[i].z));
}

TEST(IpBasicCompletion, FillsAConstantPlaneWithItsDepth) {
  // A fronto-parallel wall at 12 m sampled every 3 pixels: every pixel below the top ring is 12 m.
  cv::Mat depth(60, 80, CV_32FC1, cv::Scalar(0));
  for (int v = 10; v < 60; v += 3)
    for (int u = 0; u < 80; u += 3)
      depth.at<float>(v, u) = 12.f;
  for (const auto variant : {msf::IpBasicVariant::Fast, msf::IpBasicVariant::Multiscale}) {
    msf::IpBasicConfig config;
    config.variant = variant;
    const cv::Mat dense = msf::ipBasic(depth, config);
    for (int v = 10; v < 58; ++v)
      for (int u = 0; u < 78; ++u)
        ASSERT_NEAR(dense.at<float>(v, u), 12.f, 1e-3f) << msf::toString(variant) << " " << u << "," << v;
    if (variant == msf::IpBasicVariant::Multiscale) {
      EXPECT_EQ(dense.at<float>(0, 40), 0.f); // above the top sample: no extrapolation by default
    }
  }
}

TEST(IpBasicCompletion, DepthsBeyondTheInversionOffsetAreDropped) {
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(0));
  depth(cv::Rect(0, 0, 20, 20)).setTo(150.f); // beyond max_depth_m = 100
  EXPECT_EQ(cv::countNonZero(msf::ipBasic(depth, msf::IpBasicConfig())), 0);
}

TEST(IpBasicCompletion, ConfigNamesAndErrors) {
  EXPECT_EQ(msf::parseIpBasicVariant("fast"), msf::IpBasicVariant::Fast);
  EXPECT_EQ(msf::parseIpBasicBlur("gaussian"), msf::IpBasicBlur::Gaussian);
  EXPECT_THROW(msf::parseIpBasicBlur("median"), msf::ConfigError);
  msf::IpBasicConfig c;
  c.max_depth_m = 0.f;
  EXPECT_THROW(c.validate(), msf::ConfigError);
  EXPECT_THROW(msf::ipBasic(cv::Mat(3, 3, CV_8UC1), msf::IpBasicConfig()), msf::InvalidInputError);
}

} // namespace
