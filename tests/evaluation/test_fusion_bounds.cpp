// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The bounds of a per-pixel fusion of two depth images, on hand-made pixels.
#include <msf/common/exceptions.h>
#include <msf/evaluation/fusion_bounds.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

cv::Mat row(std::initializer_list<float> values) { return cv::Mat(cv::Mat_<float>(values)).reshape(1, 1).clone(); }

TEST(FusionBounds, SelectTakesTheInputNearerTheTruthAndBlendTheNearestValueBetween) {
  //                      both, truth between | both, truth beyond | one input | none | no truth
  const cv::Mat gt = row({10.f, 30.f, 20.f, 20.f, 20.f, 0.f});
  const cv::Mat a = row({8.f, 20.f, 0.f, 15.f, 0.f, 7.f});
  const cv::Mat b = row({11.f, 25.f, 12.f, 0.f, 0.f, 9.f});
  const cv::Mat select = msf::fusionBoundDepth(gt, a, b, msf::FusionBound::Select);
  const cv::Mat blend = msf::fusionBoundDepth(gt, a, b, msf::FusionBound::Blend);
  const float want_select[] = {11.f, 25.f, 12.f, 15.f, 0.f, 7.f};
  const float want_blend[] = {10.f, 25.f, 12.f, 15.f, 0.f, 7.f};
  for (int u = 0; u < gt.cols; ++u) {
    EXPECT_EQ(select.at<float>(0, u), want_select[u]) << u;
    EXPECT_EQ(blend.at<float>(0, u), want_blend[u]) << u;
  }
  EXPECT_EQ(msf::fusionBoundName(msf::FusionBound::Select), "bound_select");
  EXPECT_EQ(msf::fusionBoundName(msf::FusionBound::Blend), "bound_blend");
}

TEST(FusionBounds, ImagesOfAnotherSizeOrTypeAreErrors) {
  const cv::Mat gt(4, 5, CV_32FC1, cv::Scalar(1)), ok(4, 5, CV_32FC1, cv::Scalar(1));
  EXPECT_THROW(msf::fusionBoundDepth(gt, ok, cv::Mat(4, 6, CV_32FC1), msf::FusionBound::Select), msf::InvalidInputError);
  EXPECT_THROW(msf::fusionBoundDepth(gt, cv::Mat(4, 5, CV_64FC1), ok, msf::FusionBound::Blend), msf::InvalidInputError);
  EXPECT_THROW(msf::fusionBoundDepth(cv::Mat(4, 5, CV_16UC1), ok, ok, msf::FusionBound::Blend), msf::InvalidInputError);
  EXPECT_THROW(msf::fusionBoundDepth(gt, cv::Mat(), ok, msf::FusionBound::Select), msf::InvalidInputError);
}

} // namespace
