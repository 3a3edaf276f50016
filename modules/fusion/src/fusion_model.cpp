#include <msf/common/exceptions.h>
#include <msf/fusion/fusion_model.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <limits>

namespace msf {

void localDisparityRange(const cv::Mat& depth, double focal_baseline, int window, cv::Mat& range) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("LiDAR depth image must be CV_32FC1 (metres)");
  if (window < 1 || window % 2 == 0)
    throw InvalidInputError("local disparity range: window must be odd and >= 1");
  const int rows = depth.rows, cols = depth.cols;
  const float fB = static_cast<float>(focal_baseline), inf = std::numeric_limits<float>::infinity();
  // Missing pixels are 0 for the maximum and +inf for the minimum, so both see only values.
  cv::Mat hi(rows, cols, CV_32FC1), lo(rows, cols, CV_32FC1);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v) {
      const float* z = depth.ptr<float>(v);
      float* h = hi.ptr<float>(v);
      float* l = lo.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        const bool ok = z[u] > 0.f && z[u] < inf;
        const float d = ok ? fB / z[u] : 0.f;
        h[u] = d;
        l[u] = ok ? d : inf;
      }
    }
  });
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(window, window));
  cv::dilate(hi, hi, kernel);
  cv::erode(lo, lo, kernel);
  range.create(rows, cols, CV_32FC1);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v) {
      const float* h = hi.ptr<float>(v);
      const float* l = lo.ptr<float>(v);
      float* out = range.ptr<float>(v);
      for (int u = 0; u < cols; ++u)
        out[u] = l[u] < inf ? h[u] - l[u] : 0.f;
    }
  });
}

LidarParallax lidarParallax(const Calibration& calibration, const DepthFusionConfig& config) {
  LidarParallax parallax;
  // The LiDAR's origin in camera 0 (y points down): above the camera when y < 0.
  const double height = -calibration.T_cam0_velo.translation().y();
  const double baseline = calibration.baselineGrey();
  if (config.parallax_check && height > 0.0 && baseline > 0.0) {
    parallax.rows_per_px = static_cast<float>(height / baseline);
    parallax.max_rows = config.parallax_max_rows;
  }
  return parallax;
}

} // namespace msf
