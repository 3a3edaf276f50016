// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/silhouette_thickness.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>

using namespace msf;

namespace {

constexpr float kJump = 0.1f, kSigmas = 1.f;

/// A wall at `wall` m over the whole image, every pixel weighing `weight`.
struct Frame {
  cv::Mat depth, weight;
  Frame(const PinholeCamera& camera, float wall, float weight_value)
      : depth(camera.height, camera.width, CV_32FC1, cv::Scalar(wall)),
        weight(camera.height, camera.width, CV_32FC1, cv::Scalar(weight_value)) {}
  cv::Mat thickness(const PinholeCamera& camera) const {
    cv::Mat t;
    silhouetteThickness(depth, weight, camera, kJump, kSigmas, t);
    return t;
  }
};

} // namespace

TEST(SilhouetteThickness, APoleInFrontOfAWallIsAsThickAsItIsWideAndTheWallIsUnbounded) {
  const PinholeCamera camera = test::smallCamera(); // 320 x 240, f 300
  Frame frame(camera, 20.f, 1.f);
  frame.depth.colRange(150, 159).setTo(12.f); // 9 pixels, top to bottom
  const cv::Mat t = frame.thickness(camera);
  ASSERT_EQ(t.type(), CV_32FC1);
  ASSERT_EQ(t.size(), frame.depth.size());
  for (int v : {0, 120, 239}) {
    EXPECT_NEAR(t.at<float>(v, 150), 9.f * 12.f / 300.f, 1e-5f); // 0.36 m
    EXPECT_NEAR(t.at<float>(v, 158), 9.f * 12.f / 300.f, 1e-5f);
    EXPECT_TRUE(std::isinf(t.at<float>(v, 149))); // the wall touches the image's borders
    EXPECT_TRUE(std::isinf(t.at<float>(v, 159)));
  }
}

TEST(SilhouetteThickness, AHorizontalBoardIsBoundedAlongItsColumns) {
  const PinholeCamera camera = test::smallCamera();
  Frame frame(camera, 20.f, 1.f);
  frame.depth.rowRange(100, 105).setTo(8.f); // 5 rows across the whole image
  const cv::Mat t = frame.thickness(camera);
  EXPECT_NEAR(t.at<float>(102, 0), 5.f * 8.f / 300.f, 1e-5f);
  EXPECT_NEAR(t.at<float>(100, 319), 5.f * 8.f / 300.f, 1e-5f);
  EXPECT_TRUE(std::isinf(t.at<float>(99, 10)));
}

TEST(SilhouetteThickness, StereosOcclusionHoleBesideTheObjectIsLookedAcross) {
  const PinholeCamera camera = test::smallCamera();
  Frame frame(camera, 20.f, 1.f);
  frame.depth.colRange(150, 159).setTo(12.f);
  frame.depth.colRange(150 - kSilhouetteMaxHole, 150).setTo(0.f); // the widest hole looked across
  EXPECT_NEAR(frame.thickness(camera).at<float>(60, 154), 0.36f, 1e-5f);
  frame.depth.col(150 - kSilhouetteMaxHole - 1).setTo(0.f); // one wider: unbounded on that side
  EXPECT_TRUE(std::isinf(frame.thickness(camera).at<float>(60, 154)));
}

TEST(SilhouetteThickness, SomethingNearerBesideItIsNoBound) {
  // A pole against a nearer post: the pole may go on behind the post.
  const PinholeCamera camera = test::smallCamera();
  Frame frame(camera, 20.f, 1.f);
  frame.depth.colRange(150, 159).setTo(12.f);
  frame.depth.colRange(159, 165).setTo(6.f);
  const cv::Mat t = frame.thickness(camera);
  EXPECT_TRUE(std::isinf(t.at<float>(60, 154)));
  EXPECT_NEAR(t.at<float>(60, 160), 6.f * 6.f / 300.f, 1e-5f); // the post, bounded by both
}

TEST(SilhouetteThickness, FarStereosNoiseDoesNotCutAWallIntoSlivers) {
  // A wall at 30 m with a disparity sigma's worth of depth noise (0.5 m): neighbours differ by
  // up to ~2 m, within the larger of 10 % of the depth and one sigma (1 m at weight 1).
  const PinholeCamera camera = test::smallCamera();
  Frame frame(camera, 30.f, 1.f);
  cv::Mat noise(frame.depth.size(), CV_32FC1);
  cv::RNG(7).fill(noise, cv::RNG::NORMAL, 0.0, 0.5);
  frame.depth += noise;
  const cv::Mat t = frame.thickness(camera);
  EXPECT_EQ(cv::countNonZero(t < 1e30f), 0);
  // The same noise on a precise surface (weight 10000, sigma 1 cm) at 3 m: 0.5 m is 17 %, and
  // bumps nearer than both neighbours by more than 10 % are bounded slivers.
  Frame precise(camera, 3.f, 10000.f);
  precise.depth += noise;
  EXPECT_GT(cv::countNonZero(precise.thickness(camera) < 1e30f), 0);
}

TEST(SilhouetteThickness, OneColumnAndEmptyImages) {
  const PinholeCamera camera = test::smallCamera();
  cv::Mat t;
  // A column 9 pixels high in front of a farther one: bounded along the column only.
  cv::Mat depth(20, 1, CV_32FC1, cv::Scalar(20.f)), weight(20, 1, CV_32FC1, cv::Scalar(1.f));
  depth.rowRange(5, 14).setTo(12.f);
  silhouetteThickness(depth, weight, camera, kJump, kSigmas, t);
  EXPECT_NEAR(t.at<float>(9, 0), 9.f * 12.f / 300.f, 1e-5f);
  EXPECT_TRUE(std::isinf(t.at<float>(0, 0)));
  silhouetteThickness(cv::Mat(0, 0, CV_32FC1), cv::Mat(0, 0, CV_32FC1), camera, kJump, kSigmas, t);
  EXPECT_TRUE(t.empty());
}

TEST(SilhouetteThickness, BadInputIsNamed) {
  const PinholeCamera camera = test::smallCamera();
  const Frame frame(camera, 20.f, 1.f);
  cv::Mat t;
  EXPECT_THROW(silhouetteThickness(cv::Mat(camera.height, camera.width, CV_64FC1, cv::Scalar(1.0)), frame.weight,
                                   camera, kJump, kSigmas, t),
               InvalidInputError);
  EXPECT_THROW(silhouetteThickness(frame.depth, frame.weight.rowRange(0, 10), camera, kJump, kSigmas, t),
               InvalidInputError);
  PinholeCamera no_focal = camera;
  no_focal.fx = 0.0;
  EXPECT_THROW(silhouetteThickness(frame.depth, frame.weight, no_focal, kJump, kSigmas, t), InvalidInputError);
  EXPECT_THROW(silhouetteThickness(frame.depth, frame.weight, camera, -0.1f, kSigmas, t), InvalidInputError);
  EXPECT_THROW(silhouetteThickness(frame.depth, frame.weight, camera, kJump, NAN, t), InvalidInputError);
}
