// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msf {

/// A stereo matcher's disparity error by its confidence (stereoConfidence), measured against
/// ground truth, beside the sigma the fusion assumes for that confidence (stereoSigmaPx:
/// fusion.stereo_sigma_min_px and stereo_sigma_max_px). The check of the fusion's uncertainty
/// model on a user's data (msf_eval_disparity -confidence, bench/bench_stereo_sigma.sh; the
/// figures in docs/results.md).
///
/// Errors are kept in a histogram per confidence bin (1/64 px over +-32 px; larger errors in
/// the end cells), so that a sequence of any length costs the same memory, and the robust
/// figures (median, 1.4826 x the median absolute deviation) are exact to a cell.
class ConfidenceCalibration {
public:
  /// Confidence bins [edges[i], edges[i + 1]), the last one closed at its upper edge. Throws
  /// InvalidInputError unless there are at least two edges, increasing, within [0, 1].
  explicit ConfidenceCalibration(std::vector<float> edges = {0.f, 0.2f, 0.4f, 0.6f, 0.8f, 0.9f, 0.97f, 1.f});

  /// Adds the pixels that have a ground truth, an estimate (CV_32FC1 disparities in pixels,
  /// <= 0 or NaN = none) and a confidence in [0, 1] (CV_32FC1). Throws InvalidInputError
  /// naming an image of the wrong type or size.
  void add(const cv::Mat& ground_truth, const cv::Mat& estimate, const cv::Mat& confidence);

  struct Row {
    float lo = 0.f, hi = 0.f;        ///< the bin's confidence range
    std::size_t pixels = 0;
    double mean_confidence = 0.0;
    double median_px = 0.0;          ///< of the signed error estimate - truth
    double robust_sigma_px = 0.0;    ///< 1.4826 x the median absolute deviation from the median
    double outlier_share = 0.0;      ///< share of errors larger than outlier_px
    double model_sigma_px = 0.0;     ///< stereoSigmaPx at the bin's mean confidence
  };

  /// One row per bin, in order (a bin without pixels has pixels == 0 and zero figures).
  /// Throws InvalidInputError for outlier_px <= 0.
  std::vector<Row> rows(const DepthFusionConfig& model, float outlier_px = 3.f) const;

  std::size_t pixels() const;

private:
  static constexpr int kCellsPerPx = 64;
  static constexpr int kHalfRangePx = 32;
  static constexpr int kCells = 2 * kHalfRangePx * kCellsPerPx;

  struct Bin {
    std::vector<std::uint64_t> cells = std::vector<std::uint64_t>(kCells, 0);
    std::size_t pixels = 0;
    double confidence_sum = 0.0;
  };

  std::vector<float> edges_;
  std::vector<Bin> bins_;
};

} // namespace msf
