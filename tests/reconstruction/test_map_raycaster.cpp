// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/map_raycaster.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>

using namespace msf;

namespace {

/// A map of two fronto-parallel walls seen from the origin: 3 m ahead on the left half of
/// the image, 5 m ahead on the right half.
TsdfVolume twoWalls() {
  TsdfVolume volume(0.05, 0.2);
  TsdfIntegrator integrator(volume);
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(3.0f));
  frame.depth.colRange(160, 320).setTo(5.0f);
  frame.weight = cv::Mat(240, 320, CV_32FC1, cv::Scalar(400.f)); // sigma 5 cm
  for (int i = 0; i < 3; ++i)
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
  return volume;
}

Eigen::Isometry3d movedBy(double x, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, 0, z);
  return T;
}

} // namespace

TEST(MapRaycaster, RendersTheSurfaceEarlierFramesSawFromANewPose) {
  const TsdfVolume volume = twoWalls();
  const MapRaycaster raycaster(volume, MapPriorConfig());
  const PinholeCamera camera = test::smallCamera();
  cv::Mat depth, weight;
  const cv::Mat all(240, 320, CV_8UC1, cv::Scalar(255));
  raycaster.render(camera, movedBy(0.0, -1.0), all, depth, weight); // a metre back
  // Left of the image's middle the near wall, 4 m ahead now; right of it the far one, 6 m:
  // within half a voxel (the map's surface near the frames' border is that far off).
  for (const int u : {60, 100, 140})
    EXPECT_NEAR(depth.at<float>(120, u), 4.0f, 0.025f) << "u " << u;
  for (const int u : {180, 220, 260})
    EXPECT_NEAR(depth.at<float>(120, u), 6.0f, 0.025f) << "u " << u;
  EXPECT_GT(weight.at<float>(120, 60), MapPriorConfig().min_weight);
  // From farther back the camera sees wider than the frames did: its border rays meet no surface.
  EXPECT_EQ(depth.at<float>(120, 2), 0.f);
  EXPECT_EQ(weight.at<float>(120, 2), 0.f);
  // Moved sideways, the near wall's edge moves across the far wall.
  raycaster.render(camera, movedBy(0.5, 0.0), all, depth, weight);
  EXPECT_NEAR(depth.at<float>(120, 60), 3.0f, 0.025f);
  EXPECT_NEAR(depth.at<float>(120, 280), 5.0f, 0.025f);
}

TEST(MapRaycaster, OnlyTheMaskedPixelsAndWithinTheDepthRange) {
  const TsdfVolume volume = twoWalls();
  const PinholeCamera camera = test::smallCamera();
  cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(100, 100, 20, 20)).setTo(1);
  mask(cv::Rect(220, 100, 20, 20)).setTo(1);
  cv::Mat depth, weight;
  MapRaycaster(volume, MapPriorConfig()).render(camera, Eigen::Isometry3d::Identity(), mask, depth, weight);
  EXPECT_EQ(cv::countNonZero(depth > 0.f), 800);
  EXPECT_EQ(cv::countNonZero((depth > 0.f) & (mask == 0)), 0);
  EXPECT_NEAR(depth.at<float>(110, 110), 3.0f, 0.01f);
  MapPriorConfig near_only;
  near_only.max_depth_m = 4.0; // the far wall lies beyond it
  MapRaycaster(volume, near_only).render(camera, Eigen::Isometry3d::Identity(), mask, depth, weight);
  EXPECT_NEAR(depth.at<float>(110, 110), 3.0f, 0.01f);
  EXPECT_EQ(depth.at<float>(110, 230), 0.f);
  MapPriorConfig well_known;
  well_known.min_weight = 1e9f; // no voxel is known that well
  MapRaycaster(volume, well_known).render(camera, Eigen::Isometry3d::Identity(), mask, depth, weight);
  EXPECT_EQ(cv::countNonZero(depth), 0);
}

TEST(MapRaycaster, FindsATiltedWallBehindMetresOfFreeSpaceAtEveryPixel) {
  // The exact distance to the wall z = 6 + 0.3 x + 0.1 y (metres, positive on the camera's
  // side) in front of it and up to a truncation behind, written voxel by voxel: from 2.5 m on,
  // the rays cross blocks and sub-blocks of free space that hold no surface before they meet it.
  const double voxel = 0.05, truncation = 0.2;
  TsdfVolume volume(voxel, truncation);
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.3, -0.1, 1.0).normalized();
  const auto distance = [&](const Eigen::Vector3d& p) {
    return (6.0 + 0.3 * p.x() + 0.1 * p.y() - p.z()) * normal.z();
  };
  for (int z = 50; z <= 170; ++z)
    for (int y = -50; y <= 50; ++y)
      for (int x = -50; x <= 50; ++x) {
        const GridIndex v(x, y, z);
        const double d = distance(volume.voxelCenter(v));
        if (d < -truncation)
          continue;
        const GridIndex b = blockOf(v), l = v - b * TsdfBlock::kSide;
        TsdfVoxel& voxel_ref = volume.allocateBlock(b).at(l.x(), l.y(), l.z());
        voxel_ref.sdf = static_cast<float>(std::min(d, truncation));
        voxel_ref.weight = 10.f;
      }
  for (TsdfBlock* block : volume.blocks())
    block->updateSigns();
  const PinholeCamera camera = test::smallCamera();
  cv::Mat depth, weight;
  const cv::Mat all(240, 320, CV_8UC1, cv::Scalar(255));
  MapRaycaster(volume, MapPriorConfig()).render(camera, Eigen::Isometry3d::Identity(), all, depth, weight);
  int checked = 0;
  for (int v = 0; v < 240; v += 3)
    for (int u = 0; u < 320; u += 3) {
      const double x = (u - camera.cx) / camera.fx, y = (v - camera.cy) / camera.fy;
      const double z = 6.0 / (1.0 - 0.3 * x - 0.1 * y); // where the pixel's ray meets the wall
      if (std::abs(x * z) > 2.2 || std::abs(y * z) > 2.2) // beyond the voxels written, with a margin
        continue;
      ASSERT_NEAR(depth.at<float>(v, u), z, 0.005) << "pixel " << u << ", " << v;
      ++checked;
    }
  EXPECT_GT(checked, 4000);
}

TEST(MapRaycaster, RefusesABadMaskAndConfig) {
  const TsdfVolume volume = twoWalls();
  const MapRaycaster raycaster(volume, MapPriorConfig());
  cv::Mat depth, weight;
  try {
    raycaster.render(test::smallCamera(), Eigen::Isometry3d::Identity(), cv::Mat(10, 10, CV_8UC1), depth, weight);
    FAIL() << "a mask of another size was taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
  }
  Eigen::Isometry3d sheared = Eigen::Isometry3d::Identity();
  sheared.linear()(0, 1) = 0.5;
  const cv::Mat all(240, 320, CV_8UC1, cv::Scalar(1));
  try {
    raycaster.render(test::smallCamera(), sheared, all, depth, weight);
    FAIL() << "a pose that is not rigid was taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("T_world_cam"), std::string::npos) << e.what();
  }
  MapPriorConfig inverted;
  inverted.min_depth_m = 50.0;
  try {
    MapRaycaster(volume, inverted);
    FAIL() << "min_depth_m beyond max_depth_m was taken";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("map_prior.max_depth_m"), std::string::npos) << e.what();
  }
}
