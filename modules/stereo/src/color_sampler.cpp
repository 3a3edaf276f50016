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
  image_ = image;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      P_[r * 4 + c] = static_cast<float>(calibration.P[camera](r, c));
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
  const float inv_fx = 1.f / camera.fx, inv_fy = 1.f / camera.fy;
  cv::parallel_for_(cv::Range(0, depth.rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const float* z = depth.ptr<float>(v);
      std::uint8_t* out = bgr.ptr<std::uint8_t>(v);
      const float y_per_z = (static_cast<float>(v) - camera.cy) * inv_fy;
      for (int u = 0; u < depth.cols; ++u)
        if (z[u] > 0.f)
          sampler.sample((static_cast<float>(u) - camera.cx) * inv_fx * z[u], y_per_z * z[u], z[u], out[3 * u + 2],
                         out[3 * u + 1], out[3 * u]);
    }
  });
}

} // namespace msf
