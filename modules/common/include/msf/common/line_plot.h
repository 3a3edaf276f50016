// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

namespace msf {

/// A small line chart drawn with OpenCV, for the figures the tools write next to their
/// tables (run time per frame, error against noise): axes with round ticks, one coloured
/// polyline with markers per series, a legend. No plotting library needed.
class LinePlot {
public:
  struct Series {
    std::string name;
    std::vector<double> x, y;  ///< same length; non-finite y values break the line
  };

  LinePlot(std::string title, std::string x_label, std::string y_label)
      : title_(std::move(title)), x_label_(std::move(x_label)), y_label_(std::move(y_label)) {}

  /// Throws InvalidInputError when x and y differ in length.
  void addSeries(const std::string& name, const std::vector<double>& x, const std::vector<double>& y);
  /// Logarithmic y axis (values <= 0 are skipped).
  void setLogY(bool log_y) { log_y_ = log_y; }
  /// Fixes the y range instead of fitting the data.
  void setYRange(double lo, double hi) { y_lo_ = lo, y_hi_ = hi; }
  /// A horizontal dashed reference line (a target), labelled.
  void addReferenceLine(double y, const std::string& label) { references_.push_back({y, label}); }

  /// BGR picture of the chart. Throws InvalidInputError when there is no finite point.
  cv::Mat render(int width = 900, int height = 520) const;

private:
  struct Reference {
    double y;
    std::string label;
  };
  struct Frame; // the data's range and where it goes on the picture

  Frame fit(int width, int height) const;
  void drawAxes(cv::Mat& image, const Frame& frame) const;
  void drawReferences(cv::Mat& image, const Frame& frame) const;
  void drawSeries(cv::Mat& image, const Frame& frame) const;

  std::string title_, x_label_, y_label_;
  std::vector<Series> series_;
  std::vector<Reference> references_;
  bool log_y_ = false;
  double y_lo_ = 0, y_hi_ = 0;
};

} // namespace msf
