// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Hand-made rectified pairs with known disparity, shared by the stereo tests.
#include <msf/io/calibration.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <random>

namespace msf::test {

/// A rectified camera rig: focal length f, principal point at the image centre, grey pair
/// baseline B, the colour camera (2) at camera 0's place.
inline Calibration syntheticCalibration(cv::Size size, double f = 500.0, double baseline_m = 0.5) {
  Calibration c;
  Calibration::Projection P = Calibration::Projection::Zero();
  P(0, 0) = P(1, 1) = f;
  P(0, 2) = size.width / 2.0;
  P(1, 2) = size.height / 2.0;
  P(2, 2) = 1.0;
  for (auto& p : c.P)
    p = P;
  c.P[1](0, 3) = -f * baseline_m;
  c.P[3](0, 3) = -f * baseline_m;
  c.image_size = size;
  c.source = "synthetic";
  return c;
}

/// Left image: smooth random texture; right image: the left shifted by `disparity(u, v)`
/// pixels (a fronto-parallel background at `background_px`, a square in front at
/// `square_px`), so that SGBM should recover the disparity exactly in the interior.
struct SyntheticPair {
  cv::Mat left, right;
  cv::Mat disparity; // CV_32F truth
  cv::Rect square;
};

inline SyntheticPair makeSyntheticPair(cv::Size size, float background_px, float square_px, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> grey(0, 255);
  // Texture wide enough for the right view to sample to the left of column 0.
  const int margin = static_cast<int>(square_px) + 8;
  cv::Mat texture(size.height, size.width + margin, CV_8UC1);
  for (int v = 0; v < texture.rows; ++v)
    for (int u = 0; u < texture.cols; ++u)
      texture.at<std::uint8_t>(v, u) = static_cast<std::uint8_t>(grey(rng));
  // A second texture for the square, so its edges are real depth edges: from an RNG of its own
  // in OpenCV's initial state (cv::randu's in a fresh process), so that a pair does not depend
  // on what ran before it.
  cv::Mat texture2 = texture.clone();
  cv::RNG().fill(texture2, cv::RNG::UNIFORM, 0, 256);
  // The right view reads up to column u + d + margin: the textures get d + 1 more columns.
  // They hold the start of the next row, which is what the reads past a row's end used to
  // see (so the images the tests were tuned on do not change); the last row's, which read
  // past the buffer (ASan: heap-buffer-overflow), are new texture.
  const int reach = static_cast<int>(std::max(background_px, square_px)) + 1;
  auto widen = [&](const cv::Mat& narrow) {
    cv::Mat wide(narrow.rows, narrow.cols + reach, CV_8UC1);
    narrow.copyTo(wide.colRange(0, narrow.cols));
    for (int v = 0; v < narrow.rows; ++v)
      for (int k = 0; k < reach; ++k)
        wide.at<std::uint8_t>(v, narrow.cols + k) =
            v + 1 < narrow.rows && k < narrow.cols ? narrow.at<std::uint8_t>(v + 1, k)
                                                   : static_cast<std::uint8_t>(grey(rng));
    return wide;
  };
  texture = widen(texture);
  texture2 = widen(texture2);
  SyntheticPair pair;
  pair.square = cv::Rect(size.width / 2, size.height / 4, size.width / 4, size.height / 2);
  pair.left.create(size, CV_8UC1);
  pair.right.create(size, CV_8UC1);
  pair.disparity.create(size, CV_32FC1);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const bool in_square = pair.square.contains(cv::Point(u, v));
      pair.left.at<std::uint8_t>(v, u) = (in_square ? texture2 : texture).at<std::uint8_t>(v, u + margin);
      pair.disparity.at<float>(v, u) = in_square ? square_px : background_px;
    }
  // Right pixel (u, v) sees what the left sees at u + d; the square occludes the background.
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const int u_square = u + static_cast<int>(square_px);
      const bool square_visible = pair.square.contains(cv::Point(u_square, v));
      pair.right.at<std::uint8_t>(v, u) = square_visible
                                              ? texture2.at<std::uint8_t>(v, u_square + margin)
                                              : texture.at<std::uint8_t>(v, u + static_cast<int>(background_px) + margin);
    }
  return pair;
}

} // namespace msf::test
