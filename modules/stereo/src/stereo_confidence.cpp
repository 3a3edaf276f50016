// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
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
  checkKeyRanges(*this);
  if (range_window_px % 2 == 0)
    throw ConfigError("stereo.confidence_range_window_px must be odd, not " + std::to_string(range_window_px));
}

namespace {

/// What stereoConfidence keeps between calls.
struct Scratch {
  static constexpr int kRangeTable = 16 * 512; ///< range terms of 0..512 px of excess, in 1/16 px

  cv::Mat for_max, for_min;     ///< valid disparities, invalid pixels 0 / +inf
  cv::Mat local_max, local_min; ///< their max / min over the window
  cv::Mat hole_distance, mask;
  float hole_distance_px = 0.f, range_scale_px = 0.f; // of the tables
  /// Every L1 distance is a whole number up to the transform's cap; the excess local range
  /// mostly a multiple of 1/16 px. Their terms are the values std::exp gives, computed once
  /// (an exp per pixel was a tenth of the stereo stage's time).
  std::vector<float> hole_term, range_term;

  void prepare(cv::Size size, const StereoConfidenceConfig& config) {
    for (cv::Mat* image : {&for_max, &for_min, &local_max, &local_min})
      image->create(size, CV_32FC1);
    hole_distance.create(size, CV_16UC1);
    if (hole_term.empty() || hole_distance_px != config.hole_distance_px) {
      hole_distance_px = config.hole_distance_px;
      const float inv_hole = 1.f / config.hole_distance_px;
      hole_term.resize(kL1DistanceCap + 1);
      for (int k = 0; k <= kL1DistanceCap; ++k)
        hole_term[k] = 1.f - std::exp(-static_cast<float>(k) * inv_hole);
    }
    if (range_term.empty() || range_scale_px != config.range_scale_px) {
      range_scale_px = config.range_scale_px;
      const float inv_scale = 1.f / config.range_scale_px;
      range_term.resize(kRangeTable);
      for (int i = 0; i < kRangeTable; ++i)
        range_term[i] = std::exp(-(static_cast<float>(i) * (1.f / 16.f)) * inv_scale);
    }
  }
};

/// A disparity row's validity (> 0 and finite: NaN fails both tests) as 255 or 0, and the
/// inputs of the local max and min: invalid pixels 0 and +inf, so that both see only valid
/// neighbours. Branch-free over restrict pointers, so that it runs in vectors.
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
  // Scratch images and term tables kept by the calling thread between frames: fresh ones
  // cost a page fault every 4 KiB (a tenth of this function's time). A thread that comes
  // back in while it waits for its workers (nested parallel loops) takes fresh ones. The
  // workers reach them through `s` (a thread_local named in a lambda is each worker's own).
  thread_local Scratch kept;
  thread_local bool kept_in_use = false;
  Scratch fresh;
  Scratch& s = kept_in_use ? fresh : kept;
  struct Release {
    bool& flag;
    bool value;
    ~Release() { flag = value; }
  } release{kept_in_use, kept_in_use};
  kept_in_use = true;
  s.prepare(disparity.size(), config);
  if (!ours)
    s.mask.create(disparity.size(), CV_8UC1);
  // One parallel pass gives the inputs of the local max and min and the holes: each row's
  // distance to its nearest hole at once (our transform's row pass), or the mask OpenCV's
  // transform needs.
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<std::uint8_t> valid_row(ours ? static_cast<std::size_t>(cols) : 0);
    for (int v = range.start; v < range.end; ++v) {
      std::uint8_t* m = ours ? valid_row.data() : s.mask.ptr<std::uint8_t>(v);
      splitRow(disparity.ptr<float>(v), cols, m, s.for_max.ptr<float>(v), s.for_min.ptr<float>(v));
      if (ours)
        l1_distance::rowPass(m, cols, s.hole_distance.ptr<std::uint16_t>(v));
    }
  });
  if (ours) {
    l1_distance::columnPass(s.hole_distance, s.hole_distance, CV_16U);
  } else {
    cv::Mat distance;
    cv::distanceTransform(s.mask, distance, cv::DIST_L1, 3, CV_32F);
    distance.convertTo(s.hole_distance, CV_16U); // whole numbers up to 8192: exact
  }

  // OpenCV's dilate and erode (vectorised, parallel) beat a separable pass fused into ours.
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(config.range_window_px, config.range_window_px));
  cv::dilate(s.for_max, s.local_max, kernel);
  cv::erode(s.for_min, s.local_min, kernel);

  cv::Mat confidence(disparity.size(), CV_32FC1);
  const float free = config.range_free_px, inv_scale = 1.f / config.range_scale_px;
  const float* const hole_term = s.hole_term.data();
  const float* const range_term = s.range_term.data();
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const std::uint16_t* dist = s.hole_distance.ptr<std::uint16_t>(v);
      const float* hi = s.local_max.ptr<float>(v);
      const float* lo = s.local_min.ptr<float>(v);
      float* __restrict c = confidence.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        float confidence_u = hole_term[dist[u]]; // 0 at a hole itself
        const float excess = hi[u] - lo[u] - free;
        if (excess > 0.f) { // few pixels, in clusters
          // A multiple of 1/16 px (SGBM's disparities) has its term in the table.
          const float sixteenths = excess * 16.f;
          const int i = sixteenths < static_cast<float>(Scratch::kRangeTable) ? static_cast<int>(sixteenths) : 0;
          confidence_u *= i > 0 && static_cast<float>(i) == sixteenths ? range_term[i] : std::exp(-excess * inv_scale);
        }
        c[u] = confidence_u;
      }
    }
  });
  return confidence;
}

} // namespace msf
