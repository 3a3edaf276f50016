// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <cstddef>

namespace msf {

/// KITTI's D1 outlier test: an estimate is bad when its disparity error exceeds both
/// abs_px and rel times the true disparity.
struct D1Threshold {
  double abs_px = 3.0;
  double rel = 0.05;

  /// Whether a disparity error of `error_px` at the true disparity `true_px` is bad.
  bool exceeded(double error_px, double true_px) const { return error_px > abs_px && error_px > rel * true_px; }
};

/// Depth-completion and disparity metrics at the pixels that have ground truth.
/// Depth errors (MAE, RMSE, iMAE, iRMSE) and the disparity error are over pixels that
/// also have an estimate; coverage and d1_all count a missing estimate as a miss.
struct DepthMetrics {
  std::size_t gt_pixels = 0;   ///< pixels with ground truth
  std::size_t estimated = 0;   ///< of those, with an estimate
  double coverage = 0;         ///< estimated / gt_pixels
  double mae_m = 0;            ///< mean |z_est - z_gt|
  double rmse_m = 0;
  double imae_per_km = 0;      ///< mean |1/z_est - 1/z_gt| in 1/km (KITTI depth completion)
  double irmse_per_km = 0;
  double d1_all = 0;           ///< share of ground-truth pixels that are bad or missing
  double d1_estimated = 0;     ///< share of estimated pixels that are bad
  double disparity_mae_px = 0; ///< mean |d_est - d_gt| (eq. 8), d = f B / z
  /// Gross errors, |z_est - z_gt| >= kGrossDepthErrorM: the estimate is on another surface.
  double gross_share = 0;      ///< share of estimated pixels with a gross error
  double gross_mae_part_m = 0; ///< their part of mae_m (their errors over all estimates)
};

/// An error this large is another surface (an edge, a thin object, foliage), not noise.
constexpr double kGrossDepthErrorM = 10.0;

/// Sums of errors over one or more frames; pixels of all frames weigh the same.
class DepthErrorAccumulator {
public:
  /// Adds the pixels of one frame. gt and estimate: CV_32FC1 depth in metres of the same
  /// size (ground truth and estimate are where > 0 and finite); mask: optional CV_8UC1 of
  /// the same size restricting the ground-truth pixels (non-zero = use). focal_baseline:
  /// f * B in px m (Calibration::focalBaseline()), for disparities. Throws InvalidInputError
  /// naming the image at fault.
  void add(const cv::Mat& gt_depth, const cv::Mat& estimated_depth, double focal_baseline,
           const cv::Mat& mask = cv::Mat(), const D1Threshold& d1 = {});
  /// Adds one pixel, for ground truth kept as a list of pixels: gt_z is its true depth (> 0;
  /// the caller leaves out pixels without), estimated_z the estimate (missing when not > 0 or
  /// not finite). focal_baseline > 0 (add checks it; here it is the caller's).
  void addPixel(float gt_z, float estimated_z, double focal_baseline, const D1Threshold& d1 = {});
  void merge(const DepthErrorAccumulator& other);
  DepthMetrics metrics() const;

private:
  std::size_t gt_pixels_ = 0, estimated_ = 0, d1_bad_ = 0, gross_ = 0;
  double abs_ = 0, sq_ = 0, inv_abs_ = 0, inv_sq_ = 0, disp_abs_ = 0, gross_abs_ = 0;
};

/// The metrics of a single frame.
DepthMetrics computeDepthMetrics(const cv::Mat& gt_depth, const cv::Mat& estimated_depth, double focal_baseline,
                                 const cv::Mat& mask = cv::Mat(), const D1Threshold& d1 = {});

} // namespace msf
