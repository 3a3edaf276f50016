// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The image-level core: organized invariants, planes, edges, threads.
#include "scenes.h"

#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/range_image/depth_interpolator.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cstring>

namespace {

msf::InterpolationConfig noFill() {
  msf::InterpolationConfig c;
  c.gaussian = false;
  return c;
}

TEST(DepthInterpolator, KeepsSizeAndEverySample) {
  const cv::Mat sparse = msf::test::sparseScene();
  cv::Mat dense;
  msf::DepthInterpolator(msf::InterpolationConfig()).interpolate(sparse, dense);
  ASSERT_EQ(dense.size(), sparse.size());
  ASSERT_EQ(dense.type(), CV_32FC1);
  for (int v = 0; v < sparse.rows; ++v)
    for (int u = 0; u < sparse.cols; ++u)
      if (sparse.at<float>(v, u) > 0.f) {
        EXPECT_EQ(dense.at<float>(v, u), sparse.at<float>(v, u)) << u << "," << v;
      }
}

TEST(DepthInterpolator, ReproducesTheGroundPlaneBetweenRings) {
  // Inverse depth is affine along the plane: linear slices bridge it exactly. (The small
  // camera's ground changes by 0.033 / m of inverse depth across a 5-row gap: more than
  // KITTI's default edge threshold, set for f = 707 px.)
  const cv::Mat sparse = msf::test::sparseScene();
  cv::Mat dense;
  msf::InterpolationConfig config = noFill();
  config.slice.jump_inv_per_m = 0.1f;
  config.slice.interpolant = msf::SliceInterpolant::Linear;
  msf::DepthInterpolator(config).interpolate(sparse, dense);
  int checked = 0;
  for (int v = 62; v < 77; ++v) // between rings on the ground, away from the box
    for (int u = 2; u < 97; ++u) {
      const float truth = msf::test::sceneDepth(u, v);
      ASSERT_GT(dense.at<float>(v, u), 0.f) << u << "," << v;
      EXPECT_NEAR(dense.at<float>(v, u), truth, 1e-4f * truth) << u << "," << v;
      ++checked;
    }
  EXPECT_GT(checked, 1000);
}

TEST(DepthInterpolator, NeverMixesTheTwoSidesOfAnEdge) {
  // Without the Gaussian pass every estimate lies on the box (5 m) or on the wall / ground
  // behind it; nothing in between across the box's outline.
  const cv::Mat sparse = msf::test::sparseScene();
  cv::Mat dense;
  msf::DepthInterpolator(noFill()).interpolate(sparse, dense);
  for (int v = 15; v < 55; ++v)
    for (int u = 25; u < 65; ++u) {
      const float z = dense.at<float>(v, u);
      if (z > 0.f) {
        EXPECT_TRUE(z == 5.f || z > 10.f) << u << "," << v << ": " << z;
      }
    }
}

TEST(DepthInterpolator, NanExactlyWhereNoSliceReaches) {
  msf::InterpolationConfig config = noFill();
  config.slice.max_gap_px = 3;
  config.slice.short_gap_px = 2;
  config.column_seed_gap_px = 0;
  cv::Mat sparse(10, 10, CV_32FC1, cv::Scalar(0));
  sparse.at<float>(2, 1) = 4.f;
  sparse.at<float>(2, 5) = 4.f; // row gap 3: bridged
  sparse.at<float>(7, 1) = 4.f; // column gap 4 below (2,1): not bridged
  cv::Mat dense;
  msf::DepthInterpolator(config).interpolate(sparse, dense);
  for (int v = 0; v < 10; ++v)
    for (int u = 0; u < 10; ++u) {
      const bool expected = (v == 2 && u >= 1 && u <= 5) || (v == 7 && u == 1);
      EXPECT_EQ(dense.at<float>(v, u) > 0.f, expected) << u << "," << v;
    }
}

TEST(DepthInterpolator, ColumnSeedsCarryRowEstimatesDownColumnsWithoutSamples) {
  // Two scan lines whose samples sit on even columns only: column 3 has no sample.
  cv::Mat sparse(12, 8, CV_32FC1, cv::Scalar(0));
  for (int u = 0; u < 8; u += 2) {
    sparse.at<float>(1, u) = 10.f;
    sparse.at<float>(9, u) = 10.f;
  }
  msf::InterpolationConfig config = noFill();
  config.column_seed_gap_px = 0;
  cv::Mat without, with;
  msf::DepthInterpolator(config).interpolate(sparse, without);
  config.column_seed_gap_px = 1;
  msf::DepthInterpolator(config).interpolate(sparse, with);
  EXPECT_EQ(without.at<float>(5, 3), 0.f);
  EXPECT_FLOAT_EQ(with.at<float>(5, 3), 10.f);
}

TEST(DepthInterpolator, CombineRules) {
  // Pixel (2, 2): a row gap of 3 between 10 and 14 m, a column gap of 1 between 20 and 20 m.
  cv::Mat sparse(5, 7, CV_32FC1, cv::Scalar(0));
  sparse.at<float>(2, 0) = 10.f;
  sparse.at<float>(2, 4) = 14.f;
  sparse.at<float>(1, 2) = 20.f;
  sparse.at<float>(3, 2) = 20.f;
  msf::InterpolationConfig config = noFill();
  config.slice.interpolant = msf::SliceInterpolant::Linear;
  config.slice.inverse_depth = false;
  config.slice.jump_abs_m = 100.f;
  config.column_seed_gap_px = 0;
  auto at = [&](msf::CombineRule rule) {
    config.combine = rule;
    cv::Mat dense;
    msf::DepthInterpolator(config).interpolate(sparse, dense);
    return dense.at<float>(2, 2);
  };
  EXPECT_FLOAT_EQ(at(msf::CombineRule::ShorterGap), 20.f); // column gap 1 < row gap 3
  EXPECT_FLOAT_EQ(at(msf::CombineRule::Average), 16.f);    // (12 + 20) / 2
  EXPECT_FLOAT_EQ(at(msf::CombineRule::Nearest), 12.f);
  EXPECT_FLOAT_EQ(at(msf::CombineRule::GapWeighted), (12.f / 4 + 20.f / 2) / (1.f / 4 + 1.f / 2));
}

TEST(DepthInterpolator, GaussianFillsSmallHolesOnlyAndLeavesEstimatesAlone) {
  // A 30 x 30 patch of samples at 8 m with a 3 x 3 hole the slices cannot bridge
  // (max gap 2) and a far-away lone pixel.
  cv::Mat sparse(40, 40, CV_32FC1, cv::Scalar(0));
  sparse(cv::Rect(0, 0, 30, 30)).setTo(8.f);
  sparse(cv::Rect(10, 10, 3, 3)).setTo(0.f);
  msf::InterpolationConfig config;
  config.slice.max_gap_px = 2;
  config.slice.short_gap_px = 1;
  config.column_seed_gap_px = 1;
  cv::Mat dense;
  msf::DepthInterpolator(config).interpolate(sparse, dense);
  for (int v = 10; v < 13; ++v)
    for (int u = 10; u < 13; ++u)
      EXPECT_FLOAT_EQ(dense.at<float>(v, u), 8.f) << u << "," << v;
  EXPECT_EQ(dense.at<float>(38, 38), 0.f); // out of reach
  EXPECT_EQ(dense.at<float>(34, 15), 0.f); // 5 rows below the patch: beyond the 9 x 9 kernel
  EXPECT_FLOAT_EQ(dense.at<float>(31, 15), 8.f); // 2 rows below: within reach, enough weight
}

TEST(DepthInterpolator, SmoothValidAveragesInterpolatedPixelsButNeverSamples) {
  cv::Mat sparse(9, 9, CV_32FC1, cv::Scalar(0));
  for (int u = 0; u < 9; u += 2)
    for (int v = 0; v < 9; ++v)
      sparse.at<float>(v, u) = u < 4 ? 10.f : 11.f;
  msf::InterpolationConfig config;
  config.slice.jump_abs_m = 5.f;
  config.gaussian_smooth_valid = true;
  cv::Mat smooth, plain;
  msf::DepthInterpolator(config).interpolate(sparse, smooth);
  config.gaussian_smooth_valid = false;
  msf::DepthInterpolator(config).interpolate(sparse, plain);
  for (int v = 0; v < 9; ++v)
    for (int u = 0; u < 9; u += 2)
      EXPECT_EQ(smooth.at<float>(v, u), sparse.at<float>(v, u));
  EXPECT_NE(smooth.at<float>(4, 5), plain.at<float>(4, 5)); // a bridged pixel, averaged
}

TEST(DepthInterpolator, SerialEqualsParallel) {
  // A larger scene with edges everywhere: the result is bitwise the same for any thread count.
  cv::Mat sparse(203, 317, CV_32FC1, cv::Scalar(0));
  cv::RNG rng(7);
  for (int v = 0; v < sparse.rows; v += 4)
    for (int u = v % 3; u < sparse.cols; u += 2)
      if (rng.uniform(0.f, 1.f) < 0.8f)
        sparse.at<float>(v, u) = ((u / 40 + v / 30) % 2 ? 6.f : 25.f) + rng.uniform(0.f, 0.5f);
  msf::InterpolationConfig config;
  cv::Mat reference;
  config.threads = 1;
  msf::DepthInterpolator(config).interpolate(sparse, reference);
  for (int threads : {2, 3, 5}) {
    config.threads = threads;
    cv::Mat dense;
    msf::DepthInterpolator(config).interpolate(sparse, dense);
    EXPECT_EQ(0, std::memcmp(dense.data, reference.data, reference.total() * sizeof(float))) << threads << " threads";
  }
}

TEST(DepthInterpolator, BuffersAreReusedAcrossFrames) {
  // The same object on two frames gives what fresh objects give.
  msf::DepthInterpolator reused;
  const cv::Mat a = msf::test::sparseScene(5, 2), b = msf::test::sparseScene(4, 3);
  cv::Mat first, second, fresh;
  reused.interpolate(a, first);
  reused.interpolate(b, second);
  msf::DepthInterpolator().interpolate(b, fresh);
  EXPECT_EQ(0, std::memcmp(second.data, fresh.data, fresh.total() * sizeof(float)));
}

TEST(DepthInterpolator, RejectsBadImagesAndBadConfigs) {
  msf::DepthInterpolator interpolator;
  cv::Mat out;
  EXPECT_THROW(interpolator.interpolate(cv::Mat(4, 4, CV_64FC1, cv::Scalar(1)), out), msf::InvalidInputError);
  EXPECT_THROW(interpolator.interpolate(cv::Mat(), out), msf::InvalidInputError);
  msf::InterpolationConfig c;
  c.slice.short_gap_px = 40;
  c.slice.max_gap_px = 20;
  try {
    c.validate();
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("interpolation.short_gap_px"), std::string::npos) << e.what();
  }
  c = msf::InterpolationConfig();
  c.gaussian_size_px = 4;
  EXPECT_THROW(interpolator.setConfig(c), msf::ConfigError);
}

TEST(DepthInterpolator, ReadsItsYamlSection) {
  msf::InterpolationConfig c;
  msf::ConfigFile::fromText("interpolation: { method: linear, max_gap_px: 12, short_gap_px: 2, combine: average, "
                            "gaussian: false, inverse_depth: false }\n",
                            "c.yaml")
      .read(c);
  EXPECT_EQ(c.slice.interpolant, msf::SliceInterpolant::Linear);
  EXPECT_EQ(c.slice.max_gap_px, 12);
  EXPECT_EQ(c.slice.short_gap_px, 2);
  EXPECT_EQ(c.combine, msf::CombineRule::Average);
  EXPECT_FALSE(c.gaussian);
  EXPECT_FALSE(c.slice.inverse_depth);
  EXPECT_EQ(c.column_seed_gap_px, 3); // default kept
  try {
    msf::ConfigFile::fromText("interpolation: { combine: median }\n", "c.yaml").read(c);
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("median"), std::string::npos);
  }
}

} // namespace
