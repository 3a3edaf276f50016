// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Depth-completion and disparity metrics on hand-made images with known answers.
#include <msf/common/exceptions.h>
#include <msf/evaluation/depth_metrics.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <limits>

namespace {

cv::Mat image(std::initializer_list<float> values, int cols) {
  cv::Mat m(static_cast<int>(values.size()) / cols, cols, CV_32FC1);
  int i = 0;
  for (float v : values)
    m.at<float>(i / cols, i % cols) = v, ++i;
  return m;
}

TEST(DepthMetrics, KnownAnswers) {
  // Ground truth at three pixels, estimates at two of them; f B = 100 px m.
  const cv::Mat gt = image({10.f, 20.f, 0.f, 5.f}, 2);
  const cv::Mat est = image({11.f, 0.f, 7.f, 5.5f}, 2);
  const msf::DepthMetrics m = msf::computeDepthMetrics(gt, est, 100.0);
  EXPECT_EQ(m.gt_pixels, 3u);
  EXPECT_EQ(m.estimated, 2u);
  EXPECT_NEAR(m.coverage, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(m.mae_m, 0.75, 1e-6);
  EXPECT_NEAR(m.rmse_m, std::sqrt((1.0 + 0.25) / 2), 1e-6);
  const double i1 = 1000.0 / 10 - 1000.0 / 11, i2 = 1000.0 / 5 - 1000.0 / 5.5;
  EXPECT_NEAR(m.imae_per_km, (i1 + i2) / 2, 1e-4);
  EXPECT_NEAR(m.irmse_per_km, std::sqrt((i1 * i1 + i2 * i2) / 2), 1e-4);
  // Disparity errors 0.909 and 1.818 px: neither is bad; the missing pixel is.
  EXPECT_NEAR(m.disparity_mae_px, (100.0 / 10 - 100.0 / 11 + 100.0 / 5 - 100.0 / 5.5) / 2, 1e-5);
  EXPECT_EQ(m.d1_estimated, 0.0);
  EXPECT_NEAR(m.d1_all, 1.0 / 3.0, 1e-12);
}

TEST(DepthMetrics, GrossErrorsAreTheEstimatesOnAnotherSurface) {
  // Errors 1, 9.99, 10 and 30 m: the last two are gross (>= 10 m); the pixel without an
  // estimate is no error at all.
  const cv::Mat gt = image({10.f, 20.f, 40.f, 50.f, 8.f}, 5);
  const cv::Mat est = image({11.f, 29.99f, 30.f, 20.f, 0.f}, 5);
  const msf::DepthMetrics m = msf::computeDepthMetrics(gt, est, 100.0);
  ASSERT_EQ(m.estimated, 4u);
  EXPECT_NEAR(m.gross_share, 0.5, 1e-12);
  EXPECT_NEAR(m.gross_mae_part_m, (10.0 + 30.0) / 4, 1e-5);
  EXPECT_LT(m.gross_mae_part_m, m.mae_m); // a part of the MAE
  // Pooled over frames like the other metrics.
  msf::DepthErrorAccumulator two;
  two.add(gt, est, 100.0);
  two.add(gt, gt, 100.0);
  EXPECT_NEAR(two.metrics().gross_share, 2.0 / 9, 1e-12); // 4 estimates, then 5 exact ones
  EXPECT_NEAR(two.metrics().gross_mae_part_m, (10.0 + 30.0) / 9, 1e-5);
}

TEST(DepthMetrics, D1NeedsBothThreePixelsAndFivePercent) {
  // f B = 100: gt 2 m is d = 50 px, gt 1 m is d = 100 px.
  const cv::Mat gt = image({2.f, 1.f, 2.f}, 3);
  const cv::Mat est = image({100.f / 53.5f, 100.f / 104.f, 100.f / 52.f}, 3);
  // errors: 3.5 px = 7 % (bad), 4 px = 4 % (not bad), 2 px (not bad).
  const msf::DepthMetrics m = msf::computeDepthMetrics(gt, est, 100.0);
  EXPECT_NEAR(m.d1_estimated, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(m.d1_all, 1.0 / 3.0, 1e-12);
  msf::D1Threshold strict;
  strict.abs_px = 1.0;
  strict.rel = 0.01;
  EXPECT_NEAR(msf::computeDepthMetrics(gt, est, 100.0, cv::Mat(), strict).d1_all, 1.0, 1e-12);
}

TEST(DepthMetrics, MaskNanAndNegativeValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat gt = image({4.f, 4.f, nan, -2.f, 4.f, 4.f}, 3);
  const cv::Mat est = image({4.f, nan, 4.f, 4.f, -1.f, 8.f}, 3);
  const msf::DepthMetrics all = msf::computeDepthMetrics(gt, est, 50.0);
  EXPECT_EQ(all.gt_pixels, 4u);
  EXPECT_EQ(all.estimated, 2u);
  cv::Mat mask = cv::Mat::zeros(2, 3, CV_8UC1);
  mask.at<std::uint8_t>(0, 0) = 1;
  mask.at<std::uint8_t>(1, 2) = 255;
  const msf::DepthMetrics masked = msf::computeDepthMetrics(gt, est, 50.0, mask);
  EXPECT_EQ(masked.gt_pixels, 2u);
  EXPECT_EQ(masked.estimated, 2u);
  EXPECT_NEAR(masked.mae_m, 2.0, 1e-6);
}

TEST(DepthMetrics, FramesPoolTheirPixels) {
  const cv::Mat g1 = image({10.f, 10.f}, 2), e1 = image({11.f, 0.f}, 2);
  const cv::Mat g2 = image({5.f, 5.f, 5.f}, 3), e2 = image({5.f, 6.f, 7.f}, 3);
  msf::DepthErrorAccumulator a, b, both;
  a.add(g1, e1, 100.0);
  b.add(g2, e2, 100.0);
  both.add(g1, e1, 100.0);
  both.add(g2, e2, 100.0);
  a.merge(b);
  const msf::DepthMetrics m = a.metrics(), n = both.metrics();
  EXPECT_EQ(m.gt_pixels, 5u);
  EXPECT_EQ(m.estimated, 4u);
  EXPECT_NEAR(m.mae_m, (1 + 0 + 1 + 2) / 4.0, 1e-6);
  EXPECT_DOUBLE_EQ(m.rmse_m, n.rmse_m);
  EXPECT_DOUBLE_EQ(m.d1_all, n.d1_all);
}

TEST(DepthMetrics, NothingToMeasureGivesNan) {
  const cv::Mat zeros = cv::Mat::zeros(3, 3, CV_32FC1);
  const msf::DepthMetrics none = msf::computeDepthMetrics(zeros, zeros, 10.0);
  EXPECT_EQ(none.gt_pixels, 0u);
  EXPECT_TRUE(std::isnan(none.coverage));
  const msf::DepthMetrics missing = msf::computeDepthMetrics(image({3.f}, 1), image({0.f}, 1), 10.0);
  EXPECT_EQ(missing.coverage, 0.0);
  EXPECT_EQ(missing.d1_all, 1.0);
  EXPECT_TRUE(std::isnan(missing.mae_m));
  EXPECT_TRUE(std::isnan(missing.gross_share));
}

TEST(DepthMetrics, BadInputsNameTheProblem) {
  const cv::Mat gt = cv::Mat::ones(4, 5, CV_32FC1);
  auto message = [&](const cv::Mat& g, const cv::Mat& e, double fB, const cv::Mat& mask = cv::Mat()) {
    try {
      msf::computeDepthMetrics(g, e, fB, mask);
    } catch (const msf::InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(gt, cv::Mat::ones(4, 6, CV_32FC1), 1.0).find("6x4"), std::string::npos);
  EXPECT_NE(message(gt, cv::Mat::ones(4, 5, CV_64FC1), 1.0).find("CV_32FC1"), std::string::npos);
  EXPECT_NE(message(cv::Mat(), gt, 1.0).find("ground-truth"), std::string::npos);
  EXPECT_NE(message(gt, gt, 0.0).find("baseline"), std::string::npos);
  EXPECT_NE(message(gt, gt, 1.0, cv::Mat::ones(2, 2, CV_8UC1)).find("mask"), std::string::npos);
}

} // namespace
