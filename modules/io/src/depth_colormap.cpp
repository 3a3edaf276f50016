// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/io/depth_colormap.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

namespace msf {

cv::Mat colorizeDepth(const cv::Mat& depth, float min_m, float max_m, bool legend) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("colorizeDepth expects a non-empty CV_32FC1 depth image");
  if (min_m <= 0.f || max_m <= 0.f) {
    std::vector<double> valid;
    valid.reserve(depth.total() / 4);
    for (int v = 0; v < depth.rows; ++v) {
      const float* row = depth.ptr<float>(v);
      for (int u = 0; u < depth.cols; ++u)
        if (std::isfinite(row[u]) && row[u] > 0.f)
          valid.push_back(row[u]);
    }
    if (min_m <= 0.f)
      min_m = valid.empty() ? 1.f : static_cast<float>(percentile(valid, 2.0));
    if (max_m <= 0.f)
      max_m = valid.empty() ? 80.f : static_cast<float>(percentile(valid, 98.0));
  }
  if (max_m <= min_m)
    max_m = min_m + 1.f;

  cv::Mat scaled(depth.size(), CV_8UC1), mask(depth.size(), CV_8UC1);
  const float scale = 255.f / (max_m - min_m);
  for (int v = 0; v < depth.rows; ++v) {
    const float* row = depth.ptr<float>(v);
    auto* s = scaled.ptr<std::uint8_t>(v);
    auto* m = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      const bool ok = std::isfinite(row[u]) && row[u] > 0.f;
      m[u] = ok ? 255 : 0;
      s[u] = ok ? cv::saturate_cast<std::uint8_t>(255.f - (row[u] - min_m) * scale) : 0;
    }
  }
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, cv::COLORMAP_TURBO);
  colour.setTo(cv::Scalar::all(0), mask == 0);
  if (!legend)
    return colour;

  // Colour bar with five labelled ticks, as tall as the text needs.
  const int bar_h = 14, text_h = 18, margin = 8;
  cv::Mat bar(bar_h + text_h + margin, colour.cols, CV_8UC3, cv::Scalar::all(255));
  const int x0 = margin, x1 = colour.cols - margin;
  cv::Mat ramp(1, x1 - x0, CV_8UC1);
  for (int i = 0; i < ramp.cols; ++i)
    ramp.at<std::uint8_t>(0, i) = cv::saturate_cast<std::uint8_t>(255 - 255 * i / std::max(1, ramp.cols - 1));
  cv::Mat ramp_colour;
  cv::applyColorMap(ramp, ramp_colour, cv::COLORMAP_TURBO);
  cv::resize(ramp_colour, ramp_colour, cv::Size(ramp.cols, bar_h), 0, 0, cv::INTER_NEAREST);
  ramp_colour.copyTo(bar(cv::Rect(x0, margin / 2, ramp.cols, bar_h)));
  for (int k = 0; k <= 4; ++k) {
    const float metres = min_m + (max_m - min_m) * static_cast<float>(k) / 4.f;
    char label[32];
    std::snprintf(label, sizeof label, k == 4 ? "%.1f m" : "%.1f", metres);
    int baseline = 0;
    const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline);
    const int x = std::clamp(x0 + (x1 - x0) * k / 4 - ts.width / 2, 0, colour.cols - ts.width);
    cv::putText(bar, label, cv::Point(x, margin / 2 + bar_h + text_h - 4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar::all(0), 1, cv::LINE_AA);
  }
  cv::Mat out;
  cv::vconcat(colour, bar, out);
  return out;
}

} // namespace msf
