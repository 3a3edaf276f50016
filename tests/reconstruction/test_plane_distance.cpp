// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/plane_distance.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>

using namespace msf;

namespace {

/// Depth of the plane n.P = c (camera frame) at each pixel, 0 where it is behind the camera.
cv::Mat planeDepth(const PinholeCamera& camera, const Eigen::Vector3f& n, float c) {
  cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(0.f));
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3f r((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.f);
      const float z = c / n.dot(r);
      depth.at<float>(v, u) = z > 0.f ? z : 0.f;
    }
  return depth;
}

/// |n.r|: the exact factor from depth difference to distance to the plane.
float exactScale(const PinholeCamera& camera, const Eigen::Vector3f& n, int u, int v) {
  return std::abs(n.dot(Eigen::Vector3f((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.f)));
}

} // namespace

TEST(PlaneDistance, FrontoParallelPlaneIsTheProjectiveDistance) {
  const PinholeCamera camera = test::smallCamera();
  cv::Mat scale;
  planeDistanceScale(cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(3.f)), camera, {}, scale);
  ASSERT_EQ(scale.size(), cv::Size(camera.width, camera.height));
  for (int v = 0; v < camera.height; v += 7)
    for (int u = 0; u < camera.width; u += 7)
      ASSERT_NEAR(scale.at<float>(v, u), 1.f, 1e-5f) << u << "," << v;
}

TEST(PlaneDistance, GroundAtAGrazingAngleGivesTheCosineToItsNormal) {
  // The road 1.65 m below the camera (y down): n = (0, 1, 0), c = 1.65. Its scale is
  // (v - cy) / fy, small near the horizon, down to min_scale.
  const PinholeCamera camera = test::smallCamera();
  const Eigen::Vector3f n(0.f, 1.f, 0.f);
  const cv::Mat depth = planeDepth(camera, n, 1.65f);
  PlaneDistanceConfig config;
  config.min_scale = 0.05f;
  cv::Mat scale;
  planeDistanceScale(depth, camera, config, scale);
  int checked = 0;
  // From 5 rows below the horizon, where the neighbours 4 rows above still see the road.
  for (int v = static_cast<int>(camera.cy) + 5; v < camera.height; ++v)
    for (int u = 0; u < camera.width; u += 5) {
      const float exact = std::max(config.min_scale, exactScale(camera, n, u, v));
      ASSERT_NEAR(scale.at<float>(v, u), exact, 1e-3f * exact + 1e-5f) << u << "," << v;
      ++checked;
    }
  EXPECT_GT(checked, 5000);
  EXPECT_FLOAT_EQ(scale.at<float>(static_cast<int>(camera.cy) + 6, 160), config.min_scale); // near the horizon
  EXPECT_NEAR(scale.at<float>(239, 160), (239 - camera.cy) / camera.fy, 1e-4f);
}

TEST(PlaneDistance, PixelsBesideAnEdgeTakeTheirOwnSurfacesSlope) {
  // A slanted wall on the left half, a far fronto-parallel wall on the right: next to the step
  // the central difference straddles both, the one-sided one stays on the pixel's own wall.
  const PinholeCamera camera = test::smallCamera();
  const Eigen::Vector3f n = Eigen::Vector3f(0.6f, 0.f, -0.8f);
  const cv::Mat slanted = planeDepth(camera, n, -2.f);
  cv::Mat depth = slanted.clone();
  depth.colRange(160, camera.width).setTo(10.f);
  cv::Mat scale;
  planeDistanceScale(depth, camera, {}, scale);
  for (int u : {150, 156, 158, 159})
    EXPECT_NEAR(scale.at<float>(100, u), exactScale(camera, n, u, 100), 1e-3f) << u;
  for (int u : {160, 161, 165, 200})
    EXPECT_NEAR(scale.at<float>(100, u), 1.f, 1e-5f) << u;
  // A lone pixel (no neighbour on a line on either side) and a hole keep the projective distance.
  depth.setTo(0.f);
  depth.at<float>(50, 50) = 2.f;
  depth.at<float>(50, 52) = 7.f;
  depth.at<float>(50, 48) = 3.f;
  depth.at<float>(52, 50) = 2.f;
  depth.at<float>(48, 50) = 2.f;
  planeDistanceScale(depth, camera, {}, scale);
  EXPECT_FLOAT_EQ(scale.at<float>(50, 50), 1.f);
  EXPECT_FLOAT_EQ(scale.at<float>(10, 10), 1.f);
}

TEST(PlaneDistance, RejectsBadInput) {
  const PinholeCamera camera = test::smallCamera();
  cv::Mat scale;
  EXPECT_THROW(planeDistanceScale(cv::Mat(10, 10, CV_16UC1), camera, {}, scale), InvalidInputError);
  PlaneDistanceConfig bad;
  bad.min_scale = 0.f;
  EXPECT_THROW(planeDistanceScale(cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.f)), camera, bad, scale), InvalidInputError);
}

TEST(SmoothSurfaceExtent, HowFarTheSurfaceGoesOnAlongItsRowAndColumn) {
  // The road (y down, 1.65 m below the camera) and, on the columns 100..199 from row 150 down,
  // a box's face 8 m away standing on it: its pixels' surface goes on only to its own edge,
  // the road's to the farthest road pixel of its column or row.
  const PinholeCamera camera = test::smallCamera();
  cv::Mat depth = planeDepth(camera, Eigen::Vector3f(0.f, 1.f, 0.f), 1.65f);
  for (int v = 150; v < camera.height; ++v)
    for (int u = 100; u < 200; ++u)
      depth.at<float>(v, u) = 8.f;
  cv::Mat extent;
  smoothSurfaceExtent(depth, PlaneDistanceConfig().max_curvature, extent);
  // On the face, the surface goes no deeper than itself.
  EXPECT_NEAR(extent.at<float>(200, 150), 0.f, 1e-5f);
  // The road right of the box: its row is one depth, its column reaches the horizon's rows.
  const float road = depth.at<float>(200, 250);
  EXPECT_GT(extent.at<float>(200, 250), depth.at<float>(static_cast<int>(camera.cy) + 3, 250) - road - 1e-3f);
  // The road just above the face's top edge: its column's run stops at the edge below it, not
  // above, so it still reaches far.
  EXPECT_GT(extent.at<float>(148, 150), 10.f);
  // Stereo-like noise (half a pixel of KITTI disparity at 20 m: 3 % of the depth) breaks the
  // road into short runs: a noisy surface is not seen to go on, and its plane's band stays short.
  cv::Mat noisy = depth.clone();
  cv::Mat noise(depth.size(), CV_32FC1);
  cv::randn(noise, 0.0, 0.03);
  noisy = noisy.mul(1.f + noise);
  cv::Mat noisy_extent;
  smoothSurfaceExtent(noisy, PlaneDistanceConfig().max_curvature, noisy_extent);
  EXPECT_LT(noisy_extent.at<float>(200, 250), 0.25f * extent.at<float>(200, 250));
  // No depth, no extent; a bad type is an error.
  depth.at<float>(230, 300) = 0.f;
  smoothSurfaceExtent(depth, 0.05f, extent);
  EXPECT_EQ(extent.at<float>(230, 300), 0.f);
  EXPECT_THROW(smoothSurfaceExtent(cv::Mat(4, 4, CV_16UC1), 0.05f, extent), InvalidInputError);
}

namespace {

/// Whether 1/z bends by more than `curvature` of itself at sample i of a line (0 = no depth).
bool bendsAt(const std::vector<float>& line, int i, float curvature) {
  auto inverse = [&](int k) { return k >= 0 && k < static_cast<int>(line.size()) && line[k] > 0.f ? 1.f / line[k] : 0.f; };
  const float a = inverse(i - 1), b = inverse(i), c = inverse(i + 1);
  return a > 0.f && b > 0.f && c > 0.f && std::abs(a + c - 2.f * b) > curvature * b;
}

/// The largest depth of sample i's run along a line, walking out from it one sample at a time.
float runLargest(const std::vector<float>& line, int i, float curvature) {
  if (!(line[i] > 0.f))
    return 0.f;
  auto joined = [&](int k) { // sample k continues the run of sample k - 1
    return line[k - 1] > 0.f && line[k] > 0.f && !bendsAt(line, k, curvature) && !bendsAt(line, k - 1, curvature);
  };
  float largest = line[i];
  for (int k = i; k > 0 && joined(k); --k)
    largest = std::max(largest, line[k - 1]);
  for (int k = i + 1; k < static_cast<int>(line.size()) && joined(k); ++k)
    largest = std::max(largest, line[k]);
  return largest;
}

} // namespace

TEST(SmoothSurfaceExtent, EqualsItsDefinitionPixelByPixel) {
  // Sizes that are no multiple of the SIMD width or of the column strips, depth with holes,
  // NaN, negative values, smooth stretches and noise: the run-length passes must give, bit for
  // bit, the extent walked out from each pixel along its row and its column.
  cv::RNG rng(11);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(3, 2), cv::Size(37, 5), cv::Size(130, 17), cv::Size(67, 66)}) {
    cv::Mat depth(size, CV_32FC1);
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        const double kind = rng.uniform(0.0, 1.0);
        depth.at<float>(v, u) = kind < 0.1   ? 0.f
                                : kind < 0.13 ? std::nanf("")
                                : kind < 0.15 ? -1.f
                                : kind < 0.6  ? 5.f + 0.01f * u + 0.02f * v // a smooth surface
                                              : static_cast<float>(rng.uniform(1.0, 30.0));
      }
    const float curvature = 0.05f;
    cv::Mat extent;
    smoothSurfaceExtent(depth, curvature, extent);
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        std::vector<float> row(depth.ptr<float>(v), depth.ptr<float>(v) + size.width), column;
        for (int k = 0; k < size.height; ++k)
          column.push_back(depth.at<float>(k, u));
        const float d = depth.at<float>(v, u);
        const float expected = d > 0.f ? std::max(runLargest(row, u, curvature), runLargest(column, v, curvature)) - d : 0.f;
        ASSERT_EQ(extent.at<float>(v, u), expected) << size << " at " << u << "," << v;
      }
  }
}
