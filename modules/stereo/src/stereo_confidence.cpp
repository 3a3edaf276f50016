#include <msf/common/exceptions.h>
#include <msf/stereo/l1_distance_transform.h>
#include <msf/stereo/parallel_post_filter.h>
#include <msf/stereo/stereo_confidence.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace msf {

void StereoConfidenceConfig::validate() const {
  if (!(hole_distance_px > 0.f))
    throw ConfigError("config key 'stereo.confidence_hole_distance_px' must be > 0");
  if (range_window_px < 1 || range_window_px % 2 == 0)
    throw ConfigError("config key 'stereo.confidence_range_window_px' must be odd and >= 1, not " +
                      std::to_string(range_window_px));
  if (!(range_free_px >= 0.f))
    throw ConfigError("config key 'stereo.confidence_range_free_px' must be >= 0");
  if (!(range_scale_px > 0.f))
    throw ConfigError("config key 'stereo.confidence_range_scale_px' must be > 0");
}

namespace {
/// A disparity row's validity (> 0 and finite: NaN fails both tests) as 255 or 0, and the
/// inputs of the local max and min: invalid pixels 0 and +inf, so that both filters see only
/// valid neighbours. Branch-free over restrict pointers, so that it runs in vectors.
void splitRow(const float* __restrict d, int cols, std::uint8_t* __restrict valid, float* __restrict for_max,
              float* __restrict for_min) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int u = 0; u < cols; ++u) {
    const float x = d[u];
    const bool ok = (x > 0.f) & (x <= std::numeric_limits<float>::max());
    valid[u] = ok ? 255 : 0;
    for_max[u] = ok ? x : 0.f;
    for_min[u] = ok ? x : inf;
  }
}
} // namespace

cv::Mat stereoConfidence(const cv::Mat& disparity, const StereoConfidenceConfig& config) {
  if (disparity.type() != CV_32FC1)
    throw InvalidInputError("stereo confidence: disparity image must be CV_32FC1");
  config.validate();
  const int rows = disparity.rows, cols = disparity.cols;
  const bool ours = parallelPostFilterEnabled();
  // One parallel pass gives the inputs of the local max and min and the holes: each row's
  // distance to its nearest hole at once (our transform's row pass), or the mask OpenCV's
  // transform needs.
  cv::Mat for_max(disparity.size(), CV_32FC1), for_min(disparity.size(), CV_32FC1);
  cv::Mat hole_distance(disparity.size(), CV_16UC1), mask;
  if (!ours)
    mask.create(disparity.size(), CV_8UC1);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<std::uint8_t> valid_row(ours ? static_cast<std::size_t>(cols) : 0);
    for (int v = range.start; v < range.end; ++v) {
      std::uint8_t* m = ours ? valid_row.data() : mask.ptr<std::uint8_t>(v);
      splitRow(disparity.ptr<float>(v), cols, m, for_max.ptr<float>(v), for_min.ptr<float>(v));
      if (ours)
        l1_distance::rowPass(m, cols, hole_distance.ptr<std::uint16_t>(v));
    }
  });
  if (ours) {
    l1_distance::columnPass(hole_distance, hole_distance, CV_16U);
  } else {
    cv::Mat distance;
    cv::distanceTransform(mask, distance, cv::DIST_L1, 3, CV_32F);
    distance.convertTo(hole_distance, CV_16U); // whole numbers up to 8192: exact
  }
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(config.range_window_px, config.range_window_px));
  cv::dilate(for_max, for_max, kernel);
  cv::erode(for_min, for_min, kernel);

  cv::Mat confidence(disparity.size(), CV_32FC1);
  const float inv_hole = 1.f / config.hole_distance_px, inv_scale = 1.f / config.range_scale_px;
  // The L1 distance is a whole number of pixels: its term comes from a table of the values
  // std::exp gives (an exp per pixel was a tenth of the stereo stage's time).
  constexpr int kTable = 1024;
  std::vector<float> hole_term(kTable);
  for (int k = 0; k < kTable; ++k)
    hole_term[k] = 1.f - std::exp(-static_cast<float>(k) * inv_hole);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const std::uint16_t* dist = hole_distance.ptr<std::uint16_t>(v);
      const float* hi = for_max.ptr<float>(v);
      const float* lo = for_min.ptr<float>(v);
      float* c = confidence.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        const int k = dist[u];
        if (k == 0) { // a hole itself
          c[u] = 0.f;
          continue;
        }
        const float excess = std::max(0.f, hi[u] - lo[u] - config.range_free_px);
        const float hole = k < kTable ? hole_term[k] : 1.f - std::exp(-static_cast<float>(k) * inv_hole);
        c[u] = excess > 0.f ? hole * std::exp(-excess * inv_scale) : hole; // most pixels: no excess
      }
    }
  });
  return confidence;
}

} // namespace msf
