// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <cstddef>

namespace msf {

/// The KITTI 2015 devkit's disparity evaluation (protocol 1, docs/design.md), and the paper's
/// eq. 8 mean absolute disparity error.
struct DisparityEvalOptions {
  float abs_threshold_px = 3.f;   ///< a pixel is bad if its error is above both thresholds
  float rel_threshold = 0.05f;    ///< ... of the ground-truth disparity
  /// The devkit's fill of missing estimates (interpolateBackground) before evaluating, so
  /// that a missing pixel is judged by its background neighbour rather than counted as bad.
  bool interpolate_background = false;
};

/// Counts of one region (background, foreground or all pixels with ground truth).
struct DisparityRegionErrors {
  std::size_t gt_pixels = 0;     ///< pixels with ground truth
  std::size_t estimated = 0;     ///< of those, with an estimate (before any interpolation)
  std::size_t bad = 0;           ///< D1 outliers among gt_pixels; a missing estimate is bad
                                 ///< unless interpolation filled it
  std::size_t bad_estimated = 0; ///< D1 outliers among the estimated pixels
  std::size_t evaluated = 0;     ///< pixels with a value to compare (estimated, or interpolated)
  double abs_error_sum = 0.0;    ///< sum of |d_est - d_gt| over the evaluated pixels

  /// D1: bad / gt_pixels (missing estimates counted as bad, the devkit's "all" figure).
  double d1() const { return gt_pixels ? static_cast<double>(bad) / gt_pixels : 0.0; }
  /// D1 over the estimated pixels only (the devkit's "result" figure).
  double d1Estimated() const { return estimated ? static_cast<double>(bad_estimated) / estimated : 0.0; }
  /// Eq. 8: mean absolute disparity error in pixels over the evaluated pixels.
  double meanAbsError() const { return evaluated ? abs_error_sum / evaluated : 0.0; }
  /// The devkit's density: estimated / gt_pixels (the coverage of protocol 2).
  double density() const { return gt_pixels ? static_cast<double>(estimated) / gt_pixels : 0.0; }

  DisparityRegionErrors& operator+=(const DisparityRegionErrors& other);
};

struct DisparityEvaluation {
  DisparityRegionErrors background; ///< object map == 0 (everything without a map)
  DisparityRegionErrors foreground; ///< object map != 0
  DisparityRegionErrors all;
  bool has_object_map = false;

  /// Accumulates another frame, so that a sequence's figures are pixel-weighted as the devkit's.
  DisparityEvaluation& operator+=(const DisparityEvaluation& other);
};

/// Evaluates `estimate` against `ground_truth` (both CV_32F disparities in pixels,
/// <= 0 or NaN = none), split by `object_map` (8- or 16-bit, 0 = background) when given.
/// Throws InvalidInputError naming the image whose type or size is wrong.
DisparityEvaluation evaluateDisparity(const cv::Mat& ground_truth, const cv::Mat& estimate,
                                      const cv::Mat& object_map = cv::Mat(),
                                      const DisparityEvalOptions& options = {});

/// The devkit's background interpolation: along each row, a gap between two estimates takes
/// the smaller (farther) of the two; gaps at the row ends take the nearest estimate; empty
/// rows above the first and below the last row with an estimate copy that row (empty rows
/// in between stay empty, as in the devkit). Returns a new CV_32F image, 0 = none.
cv::Mat interpolateBackground(const cv::Mat& disparity);

} // namespace msf
