// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

namespace msf {

/// The depth images of one frame side by side for people: each row a labelled picture.
struct DepthPanel {
  /// Adds the left grey (or colour) image.
  void addImage(const std::string& label, const cv::Mat& image);
  /// Adds a depth image (CV_32F metres, 0 = none) in false colour over [min_m, max_m];
  /// `dilate_px` > 0 thickens sparse samples so they can be seen.
  void addDepth(const std::string& label, const cv::Mat& depth, float min_m, float max_m, int dilate_px = 0);
  /// Adds |estimate - truth| in metres where both exist, black elsewhere, over [0, max_m].
  void addError(const std::string& label, const cv::Mat& estimate, const cv::Mat& truth, float max_m);

  /// The rows stacked; throws InvalidInputError when the rows differ in width or none was added.
  cv::Mat render() const;

private:
  std::vector<cv::Mat> rows_;
};

} // namespace msf
