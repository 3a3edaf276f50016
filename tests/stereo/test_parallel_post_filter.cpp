// The stereo post-processing with our parallel routines gives exactly what OpenCV's serial
// functions give (setParallelPostFilterEnabled(false)): the matcher's disparity and the
// stereo confidence, on a synthetic pair and on KITTI.
#include <msf/stereo/parallel_post_filter.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/stereo_confidence.h>

#include "post_filter_data.h"
#include "stereo_scenes.h"

#include <cmath>
#include <limits>

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

TEST(ParallelPostFilter, EnabledByDefault) { EXPECT_TRUE(msf::parallelPostFilterEnabled()); }

TEST(ParallelPostFilter, MatcherGivesOpenCvsResultOnASyntheticPair) {
  if (!msf::SemiGlobalMatcher::isAvailable())
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
  if (!msf::SemiGlobalMatcher::isAvailable())
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

} // namespace
