// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// l1DistanceTransform against cv::distanceTransform(mask, DIST_L1, 3): identical values on
// KITTI disparity masks and random masks of every density and awkward size.
#include <msf/common/exceptions.h>
#include <msf/stereo/l1_distance_transform.h>

#include "post_filter_data.h"

#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <random>

namespace {

void expectSameAsOpenCv(const cv::Mat& mask, const std::string& what) {
  cv::Mat ours, ours16, opencv;
  msf::l1DistanceTransform(mask, ours);
  msf::l1DistanceTransform(mask, ours16, CV_16U);
  cv::distanceTransform(mask, opencv, cv::DIST_L1, 3, CV_32F);
  ASSERT_EQ(ours.type(), CV_32FC1) << what;
  ASSERT_EQ(ours16.type(), CV_16UC1) << what;
  EXPECT_EQ(cv::countNonZero(ours != opencv), 0) << what;
  cv::Mat ours16_float;
  ours16.convertTo(ours16_float, CV_32F);
  EXPECT_EQ(cv::countNonZero(ours16_float != opencv), 0) << what;
}

TEST(L1DistanceTransform, CityBlockDistanceToASingleZero) {
  cv::Mat mask(9, 13, CV_8UC1, cv::Scalar(255));
  mask.at<std::uint8_t>(3, 4) = 0;
  cv::Mat distance;
  msf::l1DistanceTransform(mask, distance);
  for (int v = 0; v < mask.rows; ++v)
    for (int u = 0; u < mask.cols; ++u)
      ASSERT_EQ(distance.at<float>(v, u), static_cast<float>(std::abs(v - 3) + std::abs(u - 4))) << v << "," << u;
}

TEST(L1DistanceTransform, MaskWithoutZeroGivesTheCapAsOpenCv) {
  const cv::Mat mask(20, 30, CV_8UC1, cv::Scalar(1));
  cv::Mat distance;
  msf::l1DistanceTransform(mask, distance);
  EXPECT_EQ(cv::countNonZero(distance != static_cast<float>(msf::kL1DistanceCap)), 0);
  expectSameAsOpenCv(mask, "no zero");
}

TEST(L1DistanceTransform, SameAsOpenCvOnRandomMasks) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double zeros : {0.0005, 0.02, 0.3, 0.9})
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(5, 1), cv::Size(1, 7), cv::Size(3, 2), cv::Size(129, 40),
                                cv::Size(700, 300)}) {
      cv::Mat mask(size, CV_8UC1);
      for (auto it = mask.begin<std::uint8_t>(); it != mask.end<std::uint8_t>(); ++it)
        *it = unit(rng) < zeros ? 0 : static_cast<std::uint8_t>(1 + rng() % 255);
      expectSameAsOpenCv(mask, "zeros " + std::to_string(zeros) + " size " + std::to_string(size.width) + "x" +
                                   std::to_string(size.height));
    }
}

TEST(L1DistanceTransform, SameAsOpenCvOnAViewIntoALargerMask) {
  cv::Mat mask = msf::test::syntheticFixedDisparity(cv::Size(300, 200), 4, 0.02) > 0;
  expectSameAsOpenCv(mask(cv::Rect(17, 9, 251, 170)), "view");
}

TEST(L1DistanceTransform, SameAsOpenCvOnKittiDisparityMasks) {
  MSF_REQUIRE_KITTI();
  for (const int frame : {0, 4})
    expectSameAsOpenCv(msf::test::kittiFixedDisparity(frame, 100) > 0, "KITTI frame " + std::to_string(frame));
}

TEST(L1DistanceTransform, RejectsOtherTypes) {
  cv::Mat distance;
  EXPECT_THROW(msf::l1DistanceTransform(cv::Mat(), distance), msf::InvalidInputError);
  EXPECT_THROW(msf::l1DistanceTransform(cv::Mat(3, 3, CV_16SC1, cv::Scalar(1)), distance), msf::InvalidInputError);
  EXPECT_THROW(msf::l1DistanceTransform(cv::Mat(3, 3, CV_8UC1, cv::Scalar(1)), distance, CV_32S),
               msf::InvalidInputError);
}

} // namespace
