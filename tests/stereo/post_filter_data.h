// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Disparity images for the tests of the stereo post-processing routines, each checked
// against the OpenCV function it replaces: KITTI's, and synthetic ones with known regions.
#include <msf/io/image_io.h>

#include "test_support.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <random>
#include <string>

namespace msf::test {

/// OpenCV's 3-way SGBM disparity (x16, CV_16S) of KITTI odometry 04 frame `frame` at 128
/// disparities, before any speckle filter (`speckle_window` 0) or after it.
inline cv::Mat kittiFixedDisparity(int frame, int speckle_window = 0) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  const std::string seq = kittiDir() + "/odometry/sequences/04/";
  const cv::Mat left = readImage(seq + "image_0/" + name, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = readImage(seq + "image_1/" + name, cv::IMREAD_GRAYSCALE);
  cv::Mat fixed;
  cv::StereoSGBM::create(0, 128, 5, 200, 800, -1, 63, 10, speckle_window, 2, cv::StereoSGBM::MODE_SGBM_3WAY)
      ->compute(left, right, fixed);
  return fixed;
}

/// A disparity-like CV_16S image: smooth plateaus (steps of `step` between neighbours, so
/// that speckle regions form), `hole_share` of the pixels `hole` (the no-match value) and
/// single-pixel outliers, from `seed`.
inline cv::Mat syntheticFixedDisparity(cv::Size size, unsigned seed, double hole_share = 0.1, short hole = -16,
                                       int step = 16) {
  std::mt19937 rng(seed);
  cv::Mat coarse(size.height / 8 + 2, size.width / 8 + 2, CV_16SC1);
  std::uniform_int_distribution<int> level(1, 60);
  for (int v = 0; v < coarse.rows; ++v)
    for (int u = 0; u < coarse.cols; ++u)
      coarse.at<short>(v, u) = static_cast<short>(level(rng) * step);
  cv::Mat image(size, CV_16SC1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> any(-40, 1100);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      short d = coarse.at<short>(v / 8, u / 8);
      const double r = unit(rng);
      if (r < hole_share)
        d = hole;
      else if (r < hole_share + 0.05)
        d = static_cast<short>(any(rng));
      else if (r < hole_share + 0.25)
        d = static_cast<short>(d + (u % 3)); // within the speckle range of its neighbours
      image.at<short>(v, u) = d;
    }
  return image;
}

} // namespace msf::test
