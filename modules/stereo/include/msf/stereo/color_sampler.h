// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/fast_math.hpp>
#include <opencv2/core/mat.hpp>

#include <cstdint>

namespace msf {

/// Colour of a point in the rectified frame of camera 0, read by projecting it into a
/// rectified camera's image (KITTI image_2 with P[2]): nearest pixel, no allocation, so it
/// can run inside the per-pixel loops of stereo and fusion. An empty image samples nothing.
class ColorSampler {
public:
  ColorSampler() = default;
  /// `image`: CV_8UC3 (BGR) or CV_8UC1 (grey), of the calibration's image size; `camera`: 0..3.
  /// Throws InvalidInputError for another image type, size or camera index.
  ColorSampler(const cv::Mat& image, const Calibration& calibration, int camera);

  bool empty() const { return image_.empty(); }

  /// Colour of the point (x, y, z) in camera 0, in metres; false when it projects behind the
  /// camera or outside the image (r, g, b are then left as they were).
  bool sample(float x, float y, float z, std::uint8_t& r, std::uint8_t& g, std::uint8_t& b) const {
    if (image_.empty())
      return false;
    const float w = P_[8] * x + P_[9] * y + P_[10] * z + P_[11];
    if (!(w > 1e-6f))
      return false;
    const float u = (P_[0] * x + P_[1] * y + P_[2] * z + P_[3]) / w;
    const float v = (P_[4] * x + P_[5] * y + P_[6] * z + P_[7]) / w;
    const int iu = cvRound(u), iv = cvRound(v); // one instruction; std::lround is a libm call
    if (iu < 0 || iv < 0 || iu >= image_.cols || iv >= image_.rows)
      return false;
    const std::uint8_t* px = image_.ptr<std::uint8_t>(iv) + static_cast<std::ptrdiff_t>(iu) * image_.channels();
    if (image_.channels() == 3) {
      b = px[0];
      g = px[1];
      r = px[2];
    } else {
      r = g = b = px[0];
    }
    return true;
  }

  /// Row `v` of a depth image of camera 0 with intrinsics `camera`: each pixel with a depth
  /// (z > 0) that the colour camera sees gets its colour in `bgr` (3 bytes a pixel); the
  /// others are left as they were. The colours sample() finds (up to rounding at pixel
  /// borders), a row at a time.
  void sampleRow(const float* z, int cols, int v, const PinholeCamera& camera, std::uint8_t* bgr) const;

private:
  cv::Mat image_;
  float P_[12] = {};
};

/// The colour of every pixel of a depth image of camera 0 (CV_32FC1 metres, 0 = none), for
/// integrators that take a colour image: a pixel with a depth takes the colour the sampler
/// finds at its point, the others (and points the colour camera does not see) keep the pixel
/// of `fallback` (the left image, CV_8UC1 or CV_8UC3 of the depth's size). Writes CV_8UC3
/// BGR, reusing `bgr` when it has the right size. Throws InvalidInputError for a fallback of
/// another type or size.
void colorizeDepth(const cv::Mat& depth, const PinholeCamera& camera, const ColorSampler& sampler,
                   const cv::Mat& fallback, cv::Mat& bgr);

} // namespace msf
