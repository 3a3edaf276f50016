// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/confidence_calibration.h>
#include <msf/fusion/fusion_model.h>

#include "image_checks.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

ConfidenceCalibration::ConfidenceCalibration(std::vector<float> edges) : edges_(std::move(edges)) {
  if (edges_.size() < 2)
    throw InvalidInputError("confidence calibration: need at least two bin edges");
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    if (!(edges_[i] >= 0.f && edges_[i] <= 1.f))
      throw InvalidInputError("confidence calibration: bin edges must lie in [0, 1], got " + std::to_string(edges_[i]));
    if (i > 0 && !(edges_[i] > edges_[i - 1]))
      throw InvalidInputError("confidence calibration: bin edges must increase");
  }
  bins_.resize(edges_.size() - 1);
}

void ConfidenceCalibration::add(const cv::Mat& ground_truth, const cv::Mat& estimate, const cv::Mat& confidence) {
  if (ground_truth.type() != CV_32FC1)
    throw InvalidInputError("confidence calibration: the ground truth must be CV_32FC1");
  detail::requireLikeGroundTruth(estimate, "confidence calibration", "the estimate", ground_truth.size());
  detail::requireLikeGroundTruth(confidence, "confidence calibration", "the confidence", ground_truth.size());
  const float lo = edges_.front(), hi = edges_.back();
  for (int v = 0; v < ground_truth.rows; ++v) {
    const float* g = ground_truth.ptr<float>(v);
    const float* e = estimate.ptr<float>(v);
    const float* c = confidence.ptr<float>(v);
    for (int u = 0; u < ground_truth.cols; ++u) {
      // NaN fails every comparison: such a pixel is skipped.
      if (!(g[u] > 0.f && e[u] > 0.f && c[u] >= lo && c[u] <= hi))
        continue;
      // The bin: the last edge not above c (the top edge closes the last bin).
      const auto it = std::upper_bound(edges_.begin(), edges_.end(), c[u]);
      const std::size_t b = std::min<std::size_t>(static_cast<std::size_t>(it - edges_.begin()) - 1, bins_.size() - 1);
      const double cell = std::floor((static_cast<double>(e[u]) - g[u] + kHalfRangePx) * kCellsPerPx);
      Bin& bin = bins_[b];
      ++bin.cells[static_cast<std::size_t>(std::clamp(cell, 0.0, static_cast<double>(kCells - 1)))];
      ++bin.pixels;
      bin.confidence_sum += c[u];
    }
  }
}

std::size_t ConfidenceCalibration::pixels() const {
  std::size_t n = 0;
  for (const Bin& b : bins_)
    n += b.pixels;
  return n;
}

std::vector<ConfidenceCalibration::Row> ConfidenceCalibration::rows(const DepthFusionConfig& model,
                                                                    float outlier_px) const {
  if (!(outlier_px > 0.f))
    throw InvalidInputError("confidence calibration: the outlier threshold must be > 0 px");
  const double width = 1.0 / kCellsPerPx;
  auto centre = [&](int i) { return (i + 0.5) * width - kHalfRangePx; };
  std::vector<Row> out;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    const Bin& bin = bins_[b];
    Row r;
    r.lo = edges_[b];
    r.hi = edges_[b + 1];
    r.pixels = bin.pixels;
    if (bin.pixels == 0) {
      out.push_back(r);
      continue;
    }
    r.mean_confidence = bin.confidence_sum / static_cast<double>(bin.pixels);
    r.model_sigma_px = stereoSigmaPx(static_cast<float>(r.mean_confidence), model);
    // The median, linear within its cell.
    const double half = 0.5 * static_cast<double>(bin.pixels);
    double below = 0.0;
    int m = 0;
    while (below + static_cast<double>(bin.cells[m]) < half)
      below += static_cast<double>(bin.cells[m++]);
    r.median_px = centre(m) - 0.5 * width + width * (half - below) / static_cast<double>(bin.cells[m]);
    // The median absolute deviation: cells taken in order of their distance from the median,
    // from the median's cell outward on both sides.
    double taken = 0.0, deviation = 0.0;
    int left = m, right = m + 1;
    while (taken < half) {
      const double dl = left >= 0 ? r.median_px - centre(left) : HUGE_VAL;
      const double dr = right < kCells ? centre(right) - r.median_px : HUGE_VAL;
      const bool take_left = std::abs(dl) <= std::abs(dr);
      deviation = std::abs(take_left ? dl : dr);
      taken += static_cast<double>(bin.cells[take_left ? left-- : right++]);
    }
    r.robust_sigma_px = 1.4826 * deviation;
    std::uint64_t outliers = 0;
    for (int i = 0; i < kCells; ++i)
      outliers += std::abs(centre(i)) > outlier_px ? bin.cells[i] : 0;
    r.outlier_share = static_cast<double>(outliers) / static_cast<double>(bin.pixels);
    out.push_back(r);
  }
  return out;
}

} // namespace msf
