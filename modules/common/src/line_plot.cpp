// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/line_plot.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace msf {

namespace {

/// Tab10-like colours (BGR) that stay apart on white.
const cv::Scalar kColours[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},  {189, 103, 148},
                               {75, 86, 140},  {194, 119, 227}, {127, 127, 127}, {34, 189, 188}, {207, 190, 23}};

/// About `count` round tick values covering [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int count) {
  const double span = hi - lo;
  const double raw = span / std::max(1, count);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step)
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  return ticks;
}

std::string label(double v) {
  char text[32];
  if (v != 0 && (std::abs(v) >= 1e5 || std::abs(v) < 1e-3))
    std::snprintf(text, sizeof text, "%.0e", v);
  else
    std::snprintf(text, sizeof text, "%g", v);
  return text;
}

void put(cv::Mat& image, const std::string& text, cv::Point at, double scale, int align = 0) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  at.x -= align == 0 ? 0 : (align == 1 ? size.width / 2 : size.width);
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(30), 1, cv::LINE_AA);
}

} // namespace

void LinePlot::addSeries(const std::string& name, const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size())
    throw InvalidInputError("plot series '" + name + "' has " + std::to_string(x.size()) + " x values and " +
                            std::to_string(y.size()) + " y values");
  series_.push_back({name, x, y});
}

/// The data's range, y as drawn (log10 on a logarithmic axis), and the plot's area.
struct LinePlot::Frame {
  bool log_y = false;
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  cv::Rect area;

  double ty(double y) const { return log_y ? std::log10(y) : y; }
  bool usable(double y) const { return std::isfinite(y) && (!log_y || y > 0); }
  int px(double x) const { return area.x + static_cast<int>(std::lround((x - x_lo) / (x_hi - x_lo) * area.width)); }
  int py(double y) const {
    return area.y + area.height - static_cast<int>(std::lround((ty(y) - y_lo) / (y_hi - y_lo) * area.height));
  }
};

/// The range of the finite points and the reference lines (or the y range set), padded.
LinePlot::Frame LinePlot::fit(int width, int height) const {
  Frame f;
  f.log_y = log_y_;
  double x_lo = std::numeric_limits<double>::max(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (const auto& s : series_)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && f.usable(s.y[i])) {
        x_lo = std::min(x_lo, s.x[i]), x_hi = std::max(x_hi, s.x[i]);
        y_lo = std::min(y_lo, f.ty(s.y[i])), y_hi = std::max(y_hi, f.ty(s.y[i]));
      }
  if (x_lo > x_hi)
    throw InvalidInputError("plot '" + title_ + "' has no finite point");
  for (const auto& r : references_)
    if (f.usable(r.y))
      y_lo = std::min(y_lo, f.ty(r.y)), y_hi = std::max(y_hi, f.ty(r.y));
  if (y_hi > y_lo || y_lo_ != y_hi_) {
    if (y_lo_ != y_hi_)
      y_lo = f.ty(y_lo_), y_hi = f.ty(y_hi_);
  }
  if (!log_y_ && y_lo_ == y_hi_ && y_lo > 0 && y_lo < 0.5 * y_hi)
    y_lo = 0; // start linear axes at zero when the data is not far from it
  if (x_hi == x_lo)
    x_lo -= 0.5, x_hi += 0.5;
  if (y_hi == y_lo)
    y_lo -= 0.5, y_hi += 0.5;
  const double pad = 0.05 * (y_hi - y_lo);
  if (!(y_lo_ != y_hi_))
    y_hi += pad, y_lo = (y_lo == 0 && !log_y_) ? 0 : y_lo - pad;
  f.x_lo = x_lo, f.x_hi = x_hi, f.y_lo = y_lo, f.y_hi = y_hi;
  const int left = 80, right = 190, top = 44, bottom = 56;
  f.area = cv::Rect(left, top, width - left - right, height - top - bottom);
  return f;
}

/// The title, the axes' labels, the grid at round ticks (decades on a logarithmic axis), the frame.
void LinePlot::drawAxes(cv::Mat& image, const Frame& f) const {
  const cv::Rect& area = f.area;
  put(image, title_, {image.cols / 2, 28}, 0.6, 1);
  put(image, x_label_, {area.x + area.width / 2, image.rows - 14}, 0.5, 1);
  cv::Mat ylabel(24, area.height, CV_8UC3, cv::Scalar::all(255));
  put(ylabel, y_label_, {area.height / 2, 17}, 0.5, 1);
  cv::rotate(ylabel, ylabel, cv::ROTATE_90_COUNTERCLOCKWISE);
  ylabel.copyTo(image(cv::Rect(4, area.y, 24, area.height)));

  for (double t : niceTicks(f.x_lo, f.x_hi, 8)) {
    cv::line(image, {f.px(t), area.y}, {f.px(t), area.y + area.height}, cv::Scalar::all(232));
    put(image, label(t), {f.px(t), area.y + area.height + 18}, 0.42, 1);
  }
  std::vector<double> y_ticks;
  if (log_y_) {
    for (int e = static_cast<int>(std::floor(f.y_lo)); e <= static_cast<int>(std::ceil(f.y_hi)); ++e)
      if (e >= f.y_lo && e <= f.y_hi)
        y_ticks.push_back(std::pow(10.0, e));
  } else {
    y_ticks = niceTicks(f.y_lo, f.y_hi, 6);
  }
  for (double t : y_ticks) {
    cv::line(image, {area.x, f.py(t)}, {area.x + area.width, f.py(t)}, cv::Scalar::all(232));
    put(image, label(t), {area.x - 6, f.py(t) + 5}, 0.42, 2);
  }
  cv::rectangle(image, area, cv::Scalar::all(80));
}

/// Each reference line within the range, dashed and labelled at its right end.
void LinePlot::drawReferences(cv::Mat& image, const Frame& f) const {
  const cv::Rect& area = f.area;
  for (const auto& r : references_) {
    if (!f.usable(r.y) || f.ty(r.y) < f.y_lo || f.ty(r.y) > f.y_hi)
      continue;
    for (int x = area.x; x < area.x + area.width; x += 12)
      cv::line(image, {x, f.py(r.y)}, {std::min(x + 6, area.x + area.width), f.py(r.y)}, cv::Scalar(60, 60, 200), 1);
    put(image, r.label, {area.x + area.width - 4, f.py(r.y) - 5}, 0.42, 2);
  }
}

/// Each series as a polyline in its colour (markers when it has few points), broken where a
/// point is not finite, and its line of the legend.
void LinePlot::drawSeries(cv::Mat& image, const Frame& f) const {
  const cv::Rect& area = f.area;
  for (std::size_t k = 0; k < series_.size(); ++k) {
    const auto& s = series_[k];
    const cv::Scalar colour = kColours[k % (sizeof kColours / sizeof kColours[0])];
    cv::Point last(-1, -1);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !f.usable(s.y[i])) {
        last = {-1, -1};
        continue;
      }
      const cv::Point p(f.px(s.x[i]), f.py(s.y[i]));
      if (last.x >= 0)
        cv::line(image, last, p, colour, 2, cv::LINE_AA);
      if (s.x.size() <= 40)
        cv::circle(image, p, 3, colour, cv::FILLED, cv::LINE_AA);
      last = p;
    }
    const int ly = area.y + 12 + 22 * static_cast<int>(k);
    cv::line(image, {area.x + area.width + 14, ly}, {area.x + area.width + 38, ly}, colour, 2, cv::LINE_AA);
    put(image, s.name, {area.x + area.width + 44, ly + 5}, 0.45);
  }
}

cv::Mat LinePlot::render(int width, int height) const {
  const Frame frame = fit(width, height);
  cv::Mat image(height, width, CV_8UC3, cv::Scalar::all(255));
  drawAxes(image, frame);
  drawReferences(image, frame);
  drawSeries(image, frame);
  return image;
}

} // namespace msf
