// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/depth_metrics.h>

#include <cmath>
#include <string>

namespace msf {

namespace {
std::string sizeOf(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }
inline bool has(float z) { return std::isfinite(z) && z > 0.f; }
} // namespace

void DepthErrorAccumulator::add(const cv::Mat& gt_depth, const cv::Mat& estimated_depth, double focal_baseline,
                                const cv::Mat& mask, const D1Threshold& d1) {
  if (gt_depth.type() != CV_32FC1 || gt_depth.empty())
    throw InvalidInputError("depth metrics: ground-truth depth must be a non-empty CV_32FC1 image");
  if (estimated_depth.type() != CV_32FC1)
    throw InvalidInputError("depth metrics: estimated depth must be a CV_32FC1 image");
  if (estimated_depth.size() != gt_depth.size())
    throw InvalidInputError("depth metrics: estimated depth is " + sizeOf(estimated_depth) +
                            " but the ground truth is " + sizeOf(gt_depth));
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != gt_depth.size()))
    throw InvalidInputError("depth metrics: mask must be CV_8UC1 of the ground truth's size " + sizeOf(gt_depth));
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("depth metrics: focal length x baseline must be > 0, not " +
                            std::to_string(focal_baseline));
  for (int v = 0; v < gt_depth.rows; ++v) {
    const float* g = gt_depth.ptr<float>(v);
    const float* e = estimated_depth.ptr<float>(v);
    const std::uint8_t* m = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < gt_depth.cols; ++u)
      if (has(g[u]) && (!m || m[u]))
        addPixel(g[u], e[u], focal_baseline, d1);
  }
}

void DepthErrorAccumulator::addPixel(float gt_z, float estimated_z, double focal_baseline, const D1Threshold& d1) {
  ++gt_pixels_;
  if (!has(estimated_z))
    return;
  ++estimated_;
  const double zg = gt_z, ze = estimated_z;
  const double err = std::abs(ze - zg);
  abs_ += err;
  sq_ += err * err;
  if (err >= kGrossDepthErrorM) {
    ++gross_;
    gross_abs_ += err;
  }
  const double inv_zg = 1.0 / zg, inv_ze = 1.0 / ze; // each reciprocal serves both errors below
  const double inv_err = 1000.0 * std::abs(inv_ze - inv_zg); // 1/km
  inv_abs_ += inv_err;
  inv_sq_ += inv_err * inv_err;
  const double dg = focal_baseline * inv_zg, de = focal_baseline * inv_ze;
  const double disp_err = std::abs(de - dg);
  disp_abs_ += disp_err;
  if (d1.exceeded(disp_err, dg))
    ++d1_bad_;
}

void DepthErrorAccumulator::merge(const DepthErrorAccumulator& o) {
  gt_pixels_ += o.gt_pixels_;
  estimated_ += o.estimated_;
  d1_bad_ += o.d1_bad_;
  gross_ += o.gross_;
  gross_abs_ += o.gross_abs_;
  abs_ += o.abs_;
  sq_ += o.sq_;
  inv_abs_ += o.inv_abs_;
  inv_sq_ += o.inv_sq_;
  disp_abs_ += o.disp_abs_;
}

DepthMetrics DepthErrorAccumulator::metrics() const {
  DepthMetrics m;
  m.gt_pixels = gt_pixels_;
  m.estimated = estimated_;
  const double nan = std::nan("");
  m.coverage = gt_pixels_ ? static_cast<double>(estimated_) / gt_pixels_ : nan;
  m.d1_all = gt_pixels_ ? static_cast<double>(d1_bad_ + (gt_pixels_ - estimated_)) / gt_pixels_ : nan;
  if (estimated_ == 0) {
    m.mae_m = m.rmse_m = m.imae_per_km = m.irmse_per_km = m.d1_estimated = m.disparity_mae_px = nan;
    m.gross_share = m.gross_mae_part_m = nan;
    return m;
  }
  const double n = static_cast<double>(estimated_);
  m.mae_m = abs_ / n;
  m.rmse_m = std::sqrt(sq_ / n);
  m.imae_per_km = inv_abs_ / n;
  m.irmse_per_km = std::sqrt(inv_sq_ / n);
  m.d1_estimated = static_cast<double>(d1_bad_) / n;
  m.disparity_mae_px = disp_abs_ / n;
  m.gross_share = static_cast<double>(gross_) / n;
  m.gross_mae_part_m = gross_abs_ / n;
  return m;
}

DepthMetrics computeDepthMetrics(const cv::Mat& gt_depth, const cv::Mat& estimated_depth, double focal_baseline,
                                 const cv::Mat& mask, const D1Threshold& d1) {
  DepthErrorAccumulator acc;
  acc.add(gt_depth, estimated_depth, focal_baseline, mask, d1);
  return acc.metrics();
}

} // namespace msf
