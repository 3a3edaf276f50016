// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/color_sampler.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <string>

namespace msf {

ColorSampler::ColorSampler(const cv::Mat& image, const Calibration& calibration, int camera) {
  if (camera < 0 || camera > 3)
    throw InvalidInputError("colour camera index " + std::to_string(camera) + " is not 0..3");
  if (image.empty())
    return;
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1)
    throw InvalidInputError("colour image must be 8-bit BGR or grey");
  // The cameras share one rectified image size: a colour image of another size is another
  // camera's or a wrong file, and its colours would land on the wrong points.
  const cv::Size expected = calibration.image_size;
  if (expected.width > 0 && image.size() != expected)
    throw InvalidInputError("colour image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                            " but calibration '" + calibration.source + "' is " + std::to_string(expected.width) +
                            "x" + std::to_string(expected.height));
  image_ = image;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      P_[r * 4 + c] = static_cast<float>(calibration.P[camera](r, c));
}

void ColorSampler::sampleRow(const float* z, int cols, int v, const PinholeCamera& camera, std::uint8_t* bgr) const {
  if (image_.empty())
    return;
  // The point of pixel (u, v) at depth z is z (a_u, b_v, 1), so each projected coordinate
  // is z times a term affine in u, plus the camera's translation: one division a pixel.
  const float inv_fx = 1.f / camera.fx, b = (static_cast<float>(v) - camera.cy) / camera.fy;
  const float* P = P_;
  const float cu = P[1] * b + P[2], cv_ = P[5] * b + P[6], cw = P[9] * b + P[10];
  const int width = image_.cols, height = image_.rows, channels = image_.channels();
  const std::uint8_t* pixels = image_.data;
  const std::size_t step = image_.step;
  for (int u = 0; u < cols; ++u) {
    const float depth = z[u];
    if (!(depth > 0.f))
      continue;
    const float a = (static_cast<float>(u) - camera.cx) * inv_fx;
    const float w = depth * (P[8] * a + cw) + P[11];
    if (!(w > 1e-6f))
      continue;
    const float inv_w = 1.f / w;
    const int iu = cvRound((depth * (P[0] * a + cu) + P[3]) * inv_w);
    const int iv = cvRound((depth * (P[4] * a + cv_) + P[7]) * inv_w);
    if (static_cast<unsigned>(iu) >= static_cast<unsigned>(width) ||
        static_cast<unsigned>(iv) >= static_cast<unsigned>(height))
      continue;
    const std::uint8_t* px = pixels + static_cast<std::size_t>(iv) * step + static_cast<std::size_t>(iu) * channels;
    std::uint8_t* out = bgr + 3 * u;
    if (channels == 3) {
      out[0] = px[0];
      out[1] = px[1];
      out[2] = px[2];
    } else {
      out[0] = out[1] = out[2] = px[0];
    }
  }
}

void colorizeDepth(const cv::Mat& depth, const PinholeCamera& camera, const ColorSampler& sampler,
                   const cv::Mat& fallback, cv::Mat& bgr) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("colorizeDepth: the depth image must be CV_32FC1");
  if (fallback.size() != depth.size() || (fallback.type() != CV_8UC1 && fallback.type() != CV_8UC3))
    throw InvalidInputError("colorizeDepth: the fallback image must be 8-bit grey or BGR of the depth's size " +
                            std::to_string(depth.cols) + "x" + std::to_string(depth.rows));
  if (fallback.channels() == 1)
    cv::cvtColor(fallback, bgr, cv::COLOR_GRAY2BGR);
  else
    fallback.copyTo(bgr);
  if (sampler.empty())
    return;
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v)
      sampler.sampleRow(depth.ptr<float>(v), depth.cols, v, camera, bgr.ptr<std::uint8_t>(v));
  });
}

} // namespace msf
