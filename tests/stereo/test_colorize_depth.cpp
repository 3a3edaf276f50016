// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "stereo_scenes.h"

#include <msf/common/exceptions.h>
#include <msf/stereo/color_sampler.h>

#include <gtest/gtest.h>

namespace {

// A colour camera 0.5 m right of camera 0 sees the point of pixel u at depth z at column
// u - f 0.5 / z: the colour image's blue channel holds its column, so the sampled colour
// tells where each pixel's point projected.
TEST(ColorizeDepth, TakesTheColourCameraPixelOfEachPointAndTheFallbackElsewhere) {
  const cv::Size size(64, 32);
  const double f = 100.0;
  msf::Calibration calibration = msf::test::syntheticCalibration(size, f);
  calibration.P[2](0, 3) = -f * 0.5;
  const msf::PinholeCamera camera = msf::PinholeCamera::fromCalibration(calibration, 0);

  cv::Mat color(size, CV_8UC3, cv::Scalar(0, 200, 100));
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      color.at<cv::Vec3b>(v, u)[0] = static_cast<std::uint8_t>(u);
  const cv::Mat left(size, CV_8UC1, cv::Scalar(42));
  cv::Mat depth(size, CV_32FC1, cv::Scalar(0.f));
  depth.at<float>(3, 40) = 5.f;   // projects to column 40 - 100 * 0.5 / 5 = 30
  depth.at<float>(10, 20) = 2.5f; // to column 0
  depth.at<float>(20, 10) = 2.f;  // to column -15: the colour camera does not see it

  cv::Mat bgr;
  msf::colorizeDepth(depth, camera, msf::ColorSampler(color, calibration, 2), left, bgr);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.size(), size);
  EXPECT_EQ(bgr.at<cv::Vec3b>(3, 40), cv::Vec3b(30, 200, 100));
  EXPECT_EQ(bgr.at<cv::Vec3b>(10, 20), cv::Vec3b(0, 200, 100));
  EXPECT_EQ(bgr.at<cv::Vec3b>(20, 10), cv::Vec3b(42, 42, 42));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(42, 42, 42)) << "a pixel without depth keeps the fallback";

  msf::colorizeDepth(depth, camera, msf::ColorSampler(), left, bgr);
  EXPECT_EQ(bgr.at<cv::Vec3b>(3, 40), cv::Vec3b(42, 42, 42)) << "no colour image: the fallback everywhere";
}

TEST(ColorizeDepth, RejectsAFallbackOfAnotherSize) {
  const cv::Size size(64, 32);
  const msf::Calibration calibration = msf::test::syntheticCalibration(size);
  const cv::Mat depth(size, CV_32FC1, cv::Scalar(1.f));
  cv::Mat bgr;
  try {
    msf::colorizeDepth(depth, msf::PinholeCamera::fromCalibration(calibration, 0), msf::ColorSampler(),
                       cv::Mat(16, 16, CV_8UC1), bgr);
    FAIL() << "expected InvalidInputError";
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("64x32"), std::string::npos) << e.what();
  }
}

} // namespace
