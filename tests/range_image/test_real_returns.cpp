// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// realReturns: the real LiDAR returns (distance 0) of an interpolated depth image.
#include <msf/common/exceptions.h>
#include <msf/range_image/real_returns.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

TEST(RealReturns, KeepsTheDepthWhereTheDistanceIsZero) {
  const cv::Mat depth = (cv::Mat_<float>(2, 3) << 5.f, 6.f, 7.f, 0.f, 8.f, 9.f);
  const cv::Mat distance = (cv::Mat_<float>(2, 3) << 0.f, 1.f, 0.f, 0.f, 2.5f, 0.f);
  const cv::Mat sparse = msf::realReturns(depth, distance);
  const cv::Mat expected = (cv::Mat_<float>(2, 3) << 5.f, 0.f, 7.f, 0.f, 0.f, 9.f);
  ASSERT_EQ(sparse.type(), CV_32FC1);
  EXPECT_EQ(cv::norm(sparse, expected, cv::NORM_INF), 0.0);
}

TEST(RealReturns, RejectsImagesThatDoNotMatch) {
  const cv::Mat depth(2, 3, CV_32FC1, cv::Scalar(1));
  EXPECT_THROW(msf::realReturns(depth, cv::Mat(3, 2, CV_32FC1, cv::Scalar(0))), msf::InvalidInputError);
  EXPECT_THROW(msf::realReturns(depth, cv::Mat(2, 3, CV_8UC1, cv::Scalar(0))), msf::InvalidInputError);
}

} // namespace
