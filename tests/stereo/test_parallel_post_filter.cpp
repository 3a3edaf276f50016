// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The stereo post-processing with our parallel routines gives exactly what OpenCV's serial
// functions give (setParallelPostFilterEnabled(false)): the matcher's disparity and the
// stereo confidence, on a synthetic pair and on KITTI.
#include <msf/stereo/parallel_post_filter.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/stereo_confidence.h>

#include "post_filter_data.h"
#include "stereo_scenes.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace {

/// Runs `f` with OpenCV's routines, then with ours; returns both results.
template <typename F>
std::pair<cv::Mat, cv::Mat> openCvAndOurs(F f) {
  msf::setParallelPostFilterEnabled(false);
  const cv::Mat opencv = f();
  msf::setParallelPostFilterEnabled(true);
  return {opencv, f()};
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(a.reshape(1) != b.reshape(1)) == 0;
}

cv::Mat matched(const cv::Mat& left, const cv::Mat& right, int disparities) {
  msf::SemiGlobalMatcher::Params params;
  params.num_disparities = disparities;
  cv::Mat disparity;
  msf::SemiGlobalMatcher(params).compute(left, right, disparity);
  return disparity;
}

/// The confidence as stereo_confidence.h defines it, from OpenCV's distance transform,
/// dilate and erode and a std::exp per pixel: the oracle of the tables and passes.
cv::Mat referenceConfidence(const cv::Mat& disparity, const msf::StereoConfidenceConfig& config) {
  cv::Mat valid(disparity.size(), CV_8UC1), for_max(disparity.size(), CV_32FC1), for_min(disparity.size(), CV_32FC1);
  for (int v = 0; v < disparity.rows; ++v)
    for (int u = 0; u < disparity.cols; ++u) {
      const float d = disparity.at<float>(v, u);
      const bool ok = d > 0.f && std::isfinite(d);
      valid.at<std::uint8_t>(v, u) = ok ? 255 : 0;
      for_max.at<float>(v, u) = ok ? d : 0.f;
      for_min.at<float>(v, u) = ok ? d : std::numeric_limits<float>::infinity();
    }
  cv::Mat distance;
  cv::distanceTransform(valid, distance, cv::DIST_L1, 3, CV_32F);
  const cv::Mat window = cv::getStructuringElement(cv::MORPH_RECT, {config.range_window_px, config.range_window_px});
  cv::dilate(for_max, for_max, window);
  cv::erode(for_min, for_min, window);
  cv::Mat confidence(disparity.size(), CV_32FC1, cv::Scalar(0));
  for (int v = 0; v < disparity.rows; ++v)
    for (int u = 0; u < disparity.cols; ++u) {
      if (!valid.at<std::uint8_t>(v, u))
        continue;
      const float hole = 1.f - std::exp(-distance.at<float>(v, u) * (1.f / config.hole_distance_px));
      const float excess = std::max(0.f, for_max.at<float>(v, u) - for_min.at<float>(v, u) - config.range_free_px);
      confidence.at<float>(v, u) = excess > 0.f ? hole * std::exp(-excess * (1.f / config.range_scale_px)) : hole;
    }
  return confidence;
}

TEST(ParallelPostFilter, EnabledByDefault) { EXPECT_TRUE(msf::parallelPostFilterEnabled()); }

TEST(ParallelPostFilter, MatcherGivesOpenCvsResultOnASyntheticPair) {
  if (!msf::SemiGlobalMatcher::usesAvx2())
    GTEST_SKIP() << "this CPU has no AVX2: the native matcher is not run";
  const auto pair = msf::test::makeSyntheticPair(cv::Size(320, 160), 10.f, 24.f);
  const auto [opencv, ours] = openCvAndOurs([&] { return matched(pair.left, pair.right, 48); });
  EXPECT_TRUE(identical(opencv, ours));
  EXPECT_GT(cv::countNonZero(ours > 0), 320 * 160 / 2); // a real disparity image
}

TEST(ParallelPostFilter, ConfidenceGivesOpenCvsResult) {
  // Holes of every kind the confidence accepts: 0, negative, NaN, infinite.
  cv::Mat disparity;
  msf::test::syntheticFixedDisparity(cv::Size(400, 150), 8, 0.1, 0).convertTo(disparity, CV_32F, 1.0 / 16);
  disparity.at<float>(3, 5) = std::numeric_limits<float>::quiet_NaN();
  disparity.at<float>(100, 300) = std::numeric_limits<float>::infinity();
  const auto [opencv, ours] = openCvAndOurs([&] { return msf::stereoConfidence(disparity); });
  EXPECT_TRUE(identical(opencv, ours));
  EXPECT_EQ(ours.at<float>(3, 5), 0.f);
  EXPECT_EQ(ours.at<float>(100, 300), 0.f);
}

TEST(ParallelPostFilter, MatcherAndConfidenceGiveOpenCvsResultOnKitti) {
  MSF_REQUIRE_KITTI();
  if (!msf::SemiGlobalMatcher::usesAvx2())
    GTEST_SKIP() << "this CPU has no AVX2: the native matcher is not run";
  const std::string seq = msf::test::kittiDir() + "/odometry/sequences/04/";
  const cv::Mat left = msf::readImage(seq + "image_0/000002.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = msf::readImage(seq + "image_1/000002.png", cv::IMREAD_GRAYSCALE);
  for (const int disparities : {128, 80}) {
    const auto [opencv, ours] = openCvAndOurs([&] { return matched(left, right, disparities); });
    EXPECT_TRUE(identical(opencv, ours)) << disparities;
    cv::Mat disparity;
    ours.convertTo(disparity, CV_32F, 1.0 / 16);
    const auto [opencv_confidence, our_confidence] =
        openCvAndOurs([&] { return msf::stereoConfidence(disparity); });
    EXPECT_TRUE(identical(opencv_confidence, our_confidence)) << disparities;
  }
}

TEST(StereoConfidence, EqualsItsDefinitionOnOpenCvRoutines) {
  // SGBM-like disparities (multiples of 1/16 px, table terms) and arbitrary ones (std::exp),
  // with every kind of hole, for several windows and scales, called one after the other
  // (the kept tables must follow the configuration).
  cv::Mat sixteenths;
  msf::test::syntheticFixedDisparity(cv::Size(300, 120), 3, 0.1, 0).convertTo(sixteenths, CV_32F, 1.0 / 16);
  cv::Mat arbitrary(120, 300, CV_32FC1);
  cv::randu(arbitrary, -5.f, 60.f);
  arbitrary.at<float>(7, 9) = std::numeric_limits<float>::quiet_NaN();
  arbitrary.at<float>(50, 60) = std::numeric_limits<float>::infinity();
  for (const cv::Mat& disparity : {sixteenths, arbitrary})
    for (const int window : {1, 5, 7})
      for (const float hole_px : {15.f, 2000.f}) {
        msf::StereoConfidenceConfig config;
        config.range_window_px = window;
        config.hole_distance_px = hole_px;
        config.range_scale_px = window == 7 ? 0.7f : 2.f;
        const cv::Mat ours = msf::stereoConfidence(disparity, config);
        EXPECT_TRUE(identical(ours, referenceConfidence(disparity, config))) << "window " << window << " hole " << hole_px;
        EXPECT_GT(cv::countNonZero((ours > 0.f) & (ours < 1.f)), static_cast<int>(disparity.total() / 4)); // not all 0 or 1
      }
}

TEST(StereoConfidence, EqualsItsDefinitionOnKitti) {
  MSF_REQUIRE_KITTI();
  cv::Mat disparity;
  msf::test::kittiFixedDisparity(5, 100).convertTo(disparity, CV_32F, 1.0 / 16);
  const cv::Mat ours = msf::stereoConfidence(disparity);
  EXPECT_TRUE(identical(ours, referenceConfidence(disparity, {})));
}

} // namespace
