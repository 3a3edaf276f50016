// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The hold-out breakdown: which ground-truth pixels camera 0 cannot see, and the regions
// msf_holdout -breakdown reports (hand-made images with known answers, then KITTI).
#include <msf/common/exceptions.h>
#include <msf/evaluation/holdout.h>
#include <msf/evaluation/holdout_breakdown.h>
#include <msf/io/sequence.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

constexpr double kFocalBaseline = 400.0; // px m: 10 m is 40 px of disparity, 40 m is 10 px

TEST(HiddenGroundTruth, AHeldOutReturnBehindANearerInputReturnIsHidden) {
  cv::Mat gt(8, 12, CV_32FC1, cv::Scalar(0)), input(8, 12, CV_32FC1, cv::Scalar(0));
  input.at<float>(4, 4) = 10.f;  // a post 10 m away
  gt.at<float>(4, 5) = 40.f;     // background beside it, within 1 px: hidden
  gt.at<float>(3, 3) = 40.f;     // diagonal neighbour: hidden
  gt.at<float>(4, 7) = 40.f;     // 3 px away: the camera sees past the post
  gt.at<float>(5, 4) = 10.5f;    // the post itself (2 px of disparity apart): visible
  input.at<float>(1, 9) = 20.f;  // 20 px of disparity ...
  gt.at<float>(1, 10) = 21.f;    // ... against 19 px: within 3 px, the same surface
  input.at<float>(6, 1) = 40.f;  // a farther input return never hides a nearer truth
  gt.at<float>(6, 2) = 10.f;
  const cv::Mat hidden = msf::hiddenGroundTruthMask(gt, input, kFocalBaseline);
  ASSERT_EQ(hidden.type(), CV_8UC1);
  EXPECT_EQ(hidden.at<std::uint8_t>(4, 5), 255);
  EXPECT_EQ(hidden.at<std::uint8_t>(3, 3), 255);
  EXPECT_EQ(hidden.at<std::uint8_t>(4, 7), 0);
  EXPECT_EQ(hidden.at<std::uint8_t>(5, 4), 0);
  EXPECT_EQ(hidden.at<std::uint8_t>(1, 10), 0);
  EXPECT_EQ(hidden.at<std::uint8_t>(6, 2), 0);
  EXPECT_EQ(cv::countNonZero(hidden), 2); // never where there is no ground truth
  // A wider radius reaches the return 3 px away.
  EXPECT_EQ(msf::hiddenGroundTruthMask(gt, input, kFocalBaseline, 3).at<std::uint8_t>(4, 7), 255);
}

TEST(HiddenGroundTruth, BadInputIsNamed) {
  const cv::Mat gt(8, 12, CV_32FC1, cv::Scalar(0));
  const auto message = [&](const cv::Mat& g, const cv::Mat& in, double fB, int radius) {
    try {
      msf::hiddenGroundTruthMask(g, in, fB, radius);
    } catch (const msf::InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(gt, cv::Mat(8, 11, CV_32FC1), kFocalBaseline, 1).find("input depth is 11x8"), std::string::npos);
  EXPECT_NE(message(gt, cv::Mat(8, 12, CV_8UC1), kFocalBaseline, 1).find("CV_32FC1"), std::string::npos);
  EXPECT_NE(message(cv::Mat(), gt, kFocalBaseline, 1).find("empty"), std::string::npos);
  EXPECT_NE(message(gt, gt, 0.0, 1).find("baseline"), std::string::npos);
  EXPECT_NE(message(gt, gt, kFocalBaseline, -1).find("radius"), std::string::npos);
}

TEST(HoldoutRegions, VisibilityAndDepthBandsEachSplitTheGroundTruth) {
  cv::Mat gt(6, 6, CV_32FC1, cv::Scalar(0)), input(6, 6, CV_32FC1, cv::Scalar(0));
  gt.at<float>(0, 0) = 5.f;
  gt.at<float>(0, 5) = 25.f;
  gt.at<float>(5, 0) = 60.f;
  gt.at<float>(5, 5) = 19.99f;
  input.at<float>(4, 1) = 5.f; // hides the 60 m return at (5, 0)
  const auto regions = msf::holdoutRegions(gt, input, kFocalBaseline);
  ASSERT_EQ(regions.size(), 5u);
  const auto count = [&](int r) { return cv::countNonZero(regions[r].mask); };
  EXPECT_EQ(regions[0].name, "visible");
  EXPECT_EQ(regions[1].name, "hidden");
  EXPECT_EQ(count(0), 3);
  EXPECT_EQ(count(1), 1);
  EXPECT_NE(regions[1].mask.at<std::uint8_t>(5, 0), 0);
  EXPECT_EQ(count(2), 2); // 5 m and 19.99 m
  EXPECT_EQ(count(3), 1);
  EXPECT_EQ(count(4), 1);
}

TEST(HoldoutBreakdown, RegionsOfAKittiRunAddUpToTheWhole) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  msf::HoldoutEvaluation evaluation;
  evaluation.setBreakdown(true);
  evaluation.addMethod("oracle", [&](const msf::HoldoutInput& in) {
    return msf::makeHoldoutFrame(sequence.load(in.frame, false), *in.calibration, msf::HoldoutConfig()).gt_depth;
  });
  evaluation.addMethod("30 m", [](const msf::HoldoutInput& in) {
    return cv::Mat(in.left.size(), CV_32FC1, cv::Scalar(30));
  });
  const auto results = evaluation.run(sequence, {0});
  ASSERT_EQ(results.size(), 2u);
  for (const auto& r : results) {
    ASSERT_EQ(r.regions.size(), 5u);
    const auto gt = [&](int k) { return r.regions[k].metrics.gt_pixels; };
    EXPECT_EQ(gt(0) + gt(1), r.metrics.gt_pixels);
    EXPECT_EQ(gt(2) + gt(3) + gt(4), r.metrics.gt_pixels);
    // Hidden pixels are rare: under 2 % of the ground truth on this frame.
    EXPECT_GT(gt(1), 0u);
    EXPECT_LT(static_cast<double>(gt(1)) / r.metrics.gt_pixels, 0.02);
  }
  for (const auto& region : results[0].regions) {
    EXPECT_EQ(region.metrics.coverage, 1.0) << region.region;
    EXPECT_EQ(region.metrics.d1_all, 0.0) << region.region;
  }
  // The depth bands' MAE, weighted by their estimates, is the whole MAE.
  const msf::HoldoutResult& constant = results[1];
  double parts = 0;
  for (int k = 2; k < 5; ++k)
    parts += constant.regions[k].metrics.mae_m * static_cast<double>(constant.regions[k].metrics.estimated);
  EXPECT_NEAR(parts / static_cast<double>(constant.metrics.estimated), constant.metrics.mae_m, 1e-9);
  EXPECT_GT(constant.regions[4].metrics.mae_m, 10.0); // beyond 40 m, 30 m is at least 10 m short
  const std::string table = msf::formatHoldoutBreakdown(results);
  EXPECT_NE(table.find("hidden"), std::string::npos);
  EXPECT_NE(table.find("z >= 40 m"), std::string::npos);
}

TEST(HoldoutTool, BreakdownPrintsTheRegionsOfEachMethod) {
  MSF_REQUIRE_KITTI();
  const auto r = msf::test::runTool("msf_holdout", "'" + msf::test::kittiDir() +
                                                       "/odometry/sequences/04' -frames 0:0 -methods interpolated "
                                                       "-breakdown");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* region : {"visible", "hidden", "z < 20 m", "z 20-40 m", "z >= 40 m", "MAE part", "errors >= 10 m"})
    EXPECT_NE(r.out.find(region), std::string::npos) << region;
}

} // namespace
