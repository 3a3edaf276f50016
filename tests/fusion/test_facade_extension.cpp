// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// extendFacades: a LiDAR-backed wall goes on upward over the blank pixels above it, and nothing
// else does: not the road, not a textured surface, not the sky.
#include <msf/common/exceptions.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/facade_extension.h>

#include "../stereo/stereo_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>

namespace {

constexpr int kWidth = 200, kHeight = 120;
constexpr float kWall = 10.f;     // a wall facing the camera 10 m away
constexpr int kWallTop = 20;      // rows above it are sky
constexpr int kLidarTop = 70;     // the LiDAR's depth reaches up to this row
constexpr float kLidarWeight = 1000.f; // sigma 3.2 cm

msf::PinholeCamera camera() {
  msf::PinholeCamera c;
  c.fx = c.fy = 500.f;
  c.cx = 100.f;
  c.cy = 60.f;
  c.width = kWidth;
  c.height = kHeight;
  return c;
}

/// The fused depth of a blank wall (grey 120 with noise of 2 levels) under a sky (grey 200):
/// LiDAR-backed up to kLidarTop, nothing above.
struct Wall {
  cv::Mat grey, depth, weight, free_weight;
  Wall()
      : grey(kHeight, kWidth, CV_8UC1), depth(kHeight, kWidth, CV_32FC1, cv::Scalar(0)),
        weight(kHeight, kWidth, CV_32FC1, cv::Scalar(0)) {
    cv::Mat noise(kHeight, kWidth, CV_32FC1);
    cv::RNG rng(7);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2);
    for (int v = 0; v < kHeight; ++v)
      for (int u = 0; u < kWidth; ++u)
        grey.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>((v < kWallTop ? 200.f : 120.f) + noise.at<float>(v, u));
    depth.rowRange(kLidarTop, kHeight).setTo(kWall);
    weight.rowRange(kLidarTop, kHeight).setTo(kLidarWeight);
    free_weight = weight.clone();
  }
  std::size_t run(const msf::DepthFusionConfig& config = {}) {
    return msf::extendFacades(grey, camera(), config, depth, weight, free_weight);
  }
};

TEST(FacadeExtension, ABlankWallGoesOnUpToItsTopEdge) {
  Wall wall;
  const std::size_t extended = wall.run();
  // Up each column to the wall's top edge, give or take the box filter's 2 rows.
  int lowest_top = kHeight, highest_top = 0;
  for (int u = 0; u < kWidth; ++u) {
    int v = kLidarTop - 1;
    while (v >= 0 && wall.depth.at<float>(v, u) > 0.f)
      --v;
    lowest_top = std::min(lowest_top, v + 1);
    highest_top = std::max(highest_top, v + 1);
  }
  EXPECT_GE(lowest_top, kWallTop - 2);
  EXPECT_LE(highest_top, kWallTop + 2);
  for (int v = kWallTop + 3; v < kLidarTop; ++v)
    for (int u = 0; u < kWidth; u += 7) {
      ASSERT_NEAR(wall.depth.at<float>(v, u), kWall, 1e-3f) << v << "," << u;
      // Sigma: the last anchor's, plus facade_sigma_per_m per metre above it.
      const float height = (kLidarTop - v) * kWall / 500.f;
      const float sigma = 1.f / std::sqrt(kLidarWeight) + msf::DepthFusionConfig().facade_sigma_per_m * height;
      ASSERT_NEAR(wall.weight.at<float>(v, u), 1.f / (sigma * sigma), 1e-2f) << v;
      ASSERT_EQ(wall.free_weight.at<float>(v, u), wall.weight.at<float>(v, u));
    }
  EXPECT_EQ(extended, static_cast<std::size_t>(cv::countNonZero(wall.depth.rowRange(0, kLidarTop))));
  // The sky keeps no depth, the LiDAR's rows are unchanged.
  EXPECT_EQ(cv::countNonZero(wall.depth.rowRange(0, kWallTop - 2)), 0);
  EXPECT_EQ(cv::countNonZero(wall.depth.rowRange(kLidarTop, kHeight) != kWall), 0);
}

// A dark window (grey 40) over rows 40-49 of columns 50-79 of the wall.
const cv::Rect kWindow(50, 40, 30, 10);

TEST(FacadeExtension, AWindowWithoutStereoStopsItsColumns) {
  // Nothing says the wall goes on above it: those columns go up to the window, not past it;
  // the others go on to the top.
  Wall wall;
  wall.grey(kWindow).setTo(40);
  wall.run();
  for (int u = 55; u < 75; ++u) {
    EXPECT_NEAR(wall.depth.at<float>(55, u), kWall, 1e-3f) << u;
    EXPECT_EQ(cv::countNonZero(wall.depth(cv::Rect(u, 0, 1, 45))), 0) << u;
  }
  EXPECT_NEAR(wall.depth.at<float>(30, 20), kWall, 1e-3f);
  EXPECT_NEAR(wall.depth.at<float>(30, 120), kWall, 1e-3f);
}

/// The window, with stereo (sigma 0.5 m) at `depth` on its top and bottom frames, rows 41 and 48.
Wall wallWithWindowSeenAt(float depth) {
  Wall wall;
  wall.grey(kWindow).setTo(40);
  for (int v : {kWindow.y + 1, kWindow.y + kWindow.height - 2}) {
    wall.depth(cv::Rect(kWindow.x, v, kWindow.width, 1)).setTo(depth);
    wall.weight(cv::Rect(kWindow.x, v, kWindow.width, 1)).setTo(4.f);
  }
  return wall;
}

TEST(FacadeExtension, AWindowIsCrossedWhereStereoSeesTheWall) {
  Wall wall = wallWithWindowSeenAt(kWall + 0.3f);
  wall.run();
  const float per_m = msf::DepthFusionConfig().facade_sigma_per_m;
  for (int u = 55; u < 75; ++u) {
    // Above the window the wall goes on, at its depth.
    for (int v = kWallTop + 3; v < kWindow.y - 3; ++v)
      ASSERT_NEAR(wall.depth.at<float>(v, u), kWall, 1e-3f) << v << "," << u;
    // The window is on the wall: where it had no depth it takes the wall's, its sigma with
    // 0.1 m added for a recess; its stereo (sigma 0.5 m, 0.3 m behind) is averaged with it.
    for (int v = kWindow.y + 2; v < kWindow.y + kWindow.height - 2; ++v) {
      const float sigma = 1.f / std::sqrt(kLidarWeight) + per_m * (kLidarTop - v) * kWall / 500.f;
      ASSERT_NEAR(wall.depth.at<float>(v, u), kWall, 1e-3f) << v << "," << u;
      ASSERT_NEAR(wall.weight.at<float>(v, u), 1.f / (sigma * sigma + 0.01f), 1e-2f) << v << "," << u;
    }
    const float seen = wall.depth.at<float>(kWindow.y + 1, u);
    ASSERT_GT(seen, kWall) << u;
    ASSERT_LT(seen, kWall + 0.05f) << u;
    ASSERT_GT(wall.weight.at<float>(kWindow.y + 1, u), 4.f) << u;
  }
  // With facade_max_gap_m under the window's 0.2 m (10 rows at 10 m), or 0, it stops them.
  for (float max_gap : {0.1f, 0.f}) {
    msf::DepthFusionConfig config;
    config.facade_max_gap_m = max_gap;
    Wall short_gap = wallWithWindowSeenAt(kWall + 0.3f);
    short_gap.run(config);
    for (int u = 55; u < 75; ++u)
      EXPECT_EQ(cv::countNonZero(short_gap.depth(cv::Rect(u, 0, 1, kWindow.y))), 0) << max_gap << ", " << u;
  }
}

TEST(FacadeExtension, WhatStereoSeesInFrontOfTheWallIsNotCrossed) {
  // A tree's crown, a pole, 3 m in front of the wall where the window is: 6 of its sigmas.
  Wall wall = wallWithWindowSeenAt(kWall - 3.f);
  wall.run();
  for (int u = 55; u < 75; ++u) {
    EXPECT_EQ(cv::countNonZero(wall.depth(cv::Rect(u, 0, 1, kWindow.y))), 0) << u;
    EXPECT_EQ(wall.depth.at<float>(kWindow.y + 1, u), kWall - 3.f) << u;
  }
  EXPECT_NEAR(wall.depth.at<float>(30, 120), kWall, 1e-3f);
}

TEST(FacadeExtension, AnOverexposedSkyIsNoWall) {
  // A white wall in the sun (grey 252, blank) under a sky as white: both are blank and alike,
  // but a saturated pixel shows no surface, so nothing goes on above the LiDAR.
  Wall wall;
  wall.grey.setTo(252);
  EXPECT_EQ(wall.run(), 0u);
  EXPECT_EQ(cv::countNonZero(wall.depth.rowRange(0, kLidarTop)), 0);
}

TEST(FacadeExtension, StereoThatAgreesIsAveragedWithTheWallAndAGuessIsReplaced) {
  Wall wall;
  // Far stereo (sigma 2 m) 1 m behind the wall: within its 3 sigmas, so one more estimate of
  // the wall's depth, averaged with it by inverse variance.
  wall.depth.at<float>(45, 100) = kWall + 1.f;
  wall.weight.at<float>(45, 100) = 0.25f;
  wall.free_weight.at<float>(45, 100) = 0.25f;
  wall.depth.at<float>(50, 30) = 10.05f; // within 3 sigmas of the wall
  wall.weight.at<float>(50, 30) = 25.f;
  wall.depth.at<float>(50, 60) = 14.f; // SGBM's guess on a blank wall
  wall.weight.at<float>(50, 60) = 4.f;
  wall.run();
  EXPECT_EQ(wall.depth.at<float>(50, 30), 10.05f);
  EXPECT_EQ(wall.weight.at<float>(50, 30), 25.f);
  EXPECT_NEAR(wall.depth.at<float>(50, 60), kWall, 1e-3f);
  EXPECT_GT(wall.weight.at<float>(50, 60), 25.f);
  // The column goes on above both. The first, known to 0.2 m, is an anchor the wall reached: it
  // joins the run, and its 5 cm move the run's depth a little.
  EXPECT_NEAR(wall.depth.at<float>(40, 30), kWall, 0.1f);
  EXPECT_NEAR(wall.depth.at<float>(40, 60), kWall, 1e-3f);
  EXPECT_NEAR(wall.depth.at<float>(kWallTop + 3, 30), kWall, 0.2f);
  const float sigma =
      1.f / std::sqrt(kLidarWeight) + msf::DepthFusionConfig().facade_sigma_per_m * (kLidarTop - 45) * kWall / 500.f;
  const float wall_weight = 1.f / (sigma * sigma);
  EXPECT_NEAR(wall.weight.at<float>(45, 100), wall_weight + 0.25f, 1e-2f);
  EXPECT_NEAR(wall.depth.at<float>(45, 100), (kWall * wall_weight + (kWall + 1.f) * 0.25f) / (wall_weight + 0.25f), 1e-4f);
  EXPECT_GT(wall.depth.at<float>(45, 100), kWall + 5e-4f); // moved, if by little
  EXPECT_EQ(wall.free_weight.at<float>(45, 100), wall.weight.at<float>(45, 100));
}

TEST(FacadeExtension, AColumnStopsWhereStereoSeesABuildingBehindTheWall) {
  // A building 16 m away behind the wall's top, of the wall's grey (no edge in the image):
  // stereo sees it (sigma 0.5 m: no anchor) in rows 20-45 of columns 40-79, nothing sees rows
  // 46-69.
  Wall wall;
  wall.grey.setTo(120);
  const cv::Rect behind(40, 20, 40, 26);
  wall.depth(behind).setTo(16.f);
  wall.weight(behind).setTo(4.f);
  wall.run();
  for (int u = behind.x; u < behind.x + behind.width; ++u) {
    // The wall goes on up to the building, takes its first two rows as SGBM's guesses and
    // stops at the third: the building keeps the rest.
    for (int v = 46; v < kLidarTop; ++v)
      ASSERT_NEAR(wall.depth.at<float>(v, u), kWall, 1e-3f) << v << "," << u;
    for (int v = behind.y; v <= 43; ++v) {
      ASSERT_EQ(wall.depth.at<float>(v, u), 16.f) << v << "," << u;
      ASSERT_EQ(wall.weight.at<float>(v, u), 4.f) << v << "," << u;
    }
  }
  // Where stereo sees nothing behind it, the wall goes on to the top of the image.
  EXPECT_NEAR(wall.depth.at<float>(5, 20), kWall, 1e-3f);
  EXPECT_NEAR(wall.depth.at<float>(30, 120), kWall, 1e-3f);
}

TEST(FacadeExtension, FarStereoBehindTheWallStopsItsColumnThoughItsSigmaInDepthIsWide) {
  // The building behind is 60 m away, where stereo's sigma is 12 m (1 px of disparity for
  // f B = 300 px m): 50 m behind the wall is only 4 of those sigmas in depth, but
  // 25 in inverse depth, in which stereo's error is spread evenly. The column stops as for a
  // near building: stereo's error is judged at the wall's depth, not at its own.
  Wall wall;
  wall.grey.setTo(120);
  const cv::Rect behind(40, 20, 40, 26);
  wall.depth(behind).setTo(60.f);
  wall.weight(behind).setTo(1.f / 144.f);
  wall.run();
  for (int u = behind.x; u < behind.x + behind.width; ++u) {
    for (int v = 46; v < kLidarTop; ++v)
      ASSERT_NEAR(wall.depth.at<float>(v, u), kWall, 1e-3f) << v << "," << u;
    for (int v = behind.y; v <= 43; ++v)
      ASSERT_EQ(wall.depth.at<float>(v, u), 60.f) << v << "," << u;
  }
  // A guess 2 m behind at sigma 0.5 m is 5 of its sigmas behind in inverse depth: no stop,
  // and replaced by the wall.
  Wall guessed;
  guessed.grey.setTo(120);
  guessed.depth(behind).setTo(12.f);
  guessed.weight(behind).setTo(4.f);
  guessed.run();
  for (int v = behind.y; v < kLidarTop; ++v)
    ASSERT_NEAR(guessed.depth.at<float>(v, 60), kWall, 1e-3f) << v;
}

TEST(FacadeExtension, TheWallGoesOnVerticalWhateverItsAnchorsSlope) {
  // Anchors whose inverse depth falls 4e-5 per row upward (n_y 0.2, within the bar): carried
  // on, their line would put row 25 at 10.18 m. The wall goes on at the run's own inverse
  // depth, that of its top ~5 rows (weights 0.8^k): 1 / (0.1 + 4e-5 * 4) m.
  Wall wall;
  for (int v = kLidarTop; v < kHeight; ++v)
    wall.depth.row(v).setTo(1.f / (0.1f + 4e-5f * static_cast<float>(v - kLidarTop)));
  wall.run();
  const float run_depth = 1.f / (0.1f + 4e-5f * 4.f);
  for (int u = 10; u < kWidth; u += 30) {
    EXPECT_NEAR(wall.depth.at<float>(25, u), run_depth, 0.01f) << u;
    EXPECT_EQ(wall.depth.at<float>(25, u), wall.depth.at<float>(kLidarTop - 1, u)) << u;
  }
}

TEST(FacadeExtension, NotTheRoadNorATexturedSurface) {
  // The road 1.65 m below the camera, LiDAR-backed from row 80 down, blank above it up to the
  // horizon: its line leads into the sky, and it stays where it is.
  Wall road;
  road.depth.setTo(0);
  road.weight.setTo(0);
  road.grey.setTo(100);
  for (int v = 80; v < kHeight; ++v) {
    road.depth.row(v).setTo(500.f * 1.65f / (v - 60.f));
    road.weight.row(v).setTo(kLidarWeight);
  }
  EXPECT_EQ(road.run(), 0u);
  EXPECT_EQ(cv::countNonZero(road.depth.rowRange(0, 80)), 0);
  // A wall with a texture of 4-pixel squares (grey 80 and 160) above the LiDAR: stereo's business.
  Wall textured;
  for (int v = 0; v < kLidarTop; ++v)
    for (int u = 0; u < kWidth; ++u)
      textured.grey.at<std::uint8_t>(v, u) = ((u / 4 + v / 4) % 2) ? 160 : 80;
  textured.run();
  EXPECT_LT(cv::countNonZero(textured.depth.rowRange(0, kLidarTop - 3)), kWidth / 10);
}

TEST(FacadeExtension, TheImageFusionRunsItWhenGivenTheGreyImage) {
  // DepthImageFusion (the pipeline's and msf_holdout's fusion): the LiDAR's wall alone, no
  // stereo. Without the grey image nothing lies above the LiDAR; with it the wall goes on.
  Wall wall;
  msf::DepthImageFusion fusion;
  fusion.setCalibration(msf::test::syntheticCalibration(cv::Size(kWidth, kHeight))); // camera()'s intrinsics
  const cv::Mat no_returns_away(kHeight, kWidth, CV_32FC1, cv::Scalar(0)), no_stereo = no_returns_away;
  cv::Mat fused;
  fusion.fuse(wall.depth, no_returns_away, no_stereo, cv::Mat(), fused);
  EXPECT_EQ(cv::countNonZero(fused.rowRange(0, kLidarTop)), 0);
  fusion.setInputImage(wall.grey);
  fusion.fuse(wall.depth, no_returns_away, no_stereo, cv::Mat(), fused);
  for (int v = kWallTop + 3; v < kLidarTop; v += 5)
    EXPECT_NEAR(fused.at<float>(v, 100), kWall, 1e-3f) << v;
  fusion.setInputImage(wall.grey.rowRange(0, 100));
  EXPECT_THROW(fusion.fuse(wall.depth, no_returns_away, no_stereo, cv::Mat(), fused), msf::InvalidInputError);
}

TEST(FacadeExtension, BadInputIsAClearError) {
  Wall wall;
  cv::Mat wrong_type;
  wall.depth.convertTo(wrong_type, CV_64FC1);
  EXPECT_EQ(msf::test::errorOf([&] {
              msf::extendFacades(wall.grey, camera(), {}, wrong_type, wall.weight, wall.free_weight);
            }),
            "facade extension: the depth is a 200x120 image of type 6, expected type 5 of 200x120");
  cv::Mat small_grey = wall.grey.rowRange(0, 100).clone();
  EXPECT_THROW(msf::extendFacades(small_grey, camera(), {}, wall.depth, wall.weight, wall.free_weight),
               msf::InvalidInputError);
  cv::Mat no_weight;
  EXPECT_THROW(msf::extendFacades(wall.grey, camera(), {}, wall.depth, no_weight, wall.free_weight),
               msf::InvalidInputError);
  msf::PinholeCamera other = camera();
  other.width = 100;
  EXPECT_THROW(msf::extendFacades(wall.grey, other, {}, wall.depth, wall.weight, wall.free_weight),
               msf::InvalidInputError);
  // Keys out of range are refused by name.
  msf::DepthFusionConfig config;
  config.facade_max_normal_y = 2.f;
  EXPECT_EQ(msf::test::errorOf([&] { config.validate(); }),
            "fusion.facade_max_normal_y must be in 0..1, not 2.0");
  config = {};
  config.facade_anchor_sigma_m = 0.f;
  EXPECT_THROW(config.validate(), msf::ConfigError);
  config = {};
  config.facade_max_texture = std::nanf("");
  EXPECT_THROW(config.validate(), msf::ConfigError);
  config = {};
  config.facade_max_gap_m = -1.f;
  EXPECT_THROW(config.validate(), msf::ConfigError);
}

} // namespace
