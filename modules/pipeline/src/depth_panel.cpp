// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/depth_colormap.h>
#include <msf/pipeline/depth_panel.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>

namespace msf {

namespace {

cv::Mat labelled(const std::string& label, const cv::Mat& picture) {
  cv::Mat row(picture.rows + 24, picture.cols, CV_8UC3, cv::Scalar::all(255));
  picture.copyTo(row(cv::Rect(0, 24, picture.cols, picture.rows)));
  cv::putText(row, label, {6, 17}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar::all(20), 1, cv::LINE_AA);
  return row;
}

cv::Mat toBgr(const cv::Mat& image) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  return out;
}

} // namespace

void DepthPanel::addImage(const std::string& label, const cv::Mat& image) {
  if (image.empty())
    throw InvalidInputError("depth panel row '" + label + "': empty image");
  rows_.push_back(labelled(label, toBgr(image)));
}

void DepthPanel::addDepth(const std::string& label, const cv::Mat& depth, float min_m, float max_m, int dilate_px) {
  cv::Mat shown = depth;
  if (dilate_px > 0) // grey dilation keeps the largest depth; sparse samples only need to be visible
    cv::dilate(depth, shown, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * dilate_px + 1, 2 * dilate_px + 1}));
  rows_.push_back(labelled(label, colorizeDepth(shown, min_m, max_m, false)));
}

void DepthPanel::addError(const std::string& label, const cv::Mat& estimate, const cv::Mat& truth, float max_m) {
  if (estimate.size() != truth.size() || estimate.type() != CV_32FC1 || truth.type() != CV_32FC1)
    throw InvalidInputError("depth panel row '" + label + "': estimate and truth must be CV_32FC1 of one size");
  cv::Mat scaled(estimate.size(), CV_8UC1, cv::Scalar(0)), mask(estimate.size(), CV_8UC1, cv::Scalar(0));
  double sum = 0;
  std::size_t n = 0;
  for (int v = 0; v < estimate.rows; ++v) {
    const float* e = estimate.ptr<float>(v);
    const float* t = truth.ptr<float>(v);
    for (int u = 0; u < estimate.cols; ++u)
      if (e[u] > 0.f && t[u] > 0.f && std::isfinite(e[u]) && std::isfinite(t[u])) {
        const float err = std::abs(e[u] - t[u]);
        scaled.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(255.f * err / max_m);
        mask.at<std::uint8_t>(v, u) = 255;
        sum += err;
        ++n;
      }
  }
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, cv::COLORMAP_INFERNO);
  colour.setTo(cv::Scalar::all(0), mask == 0);
  char text[160];
  std::snprintf(text, sizeof text, "%s (0 .. %.1f m, mean %.2f m over %zu px)", label.c_str(), max_m,
                n ? sum / static_cast<double>(n) : 0.0, n);
  rows_.push_back(labelled(text, colour));
}

cv::Mat DepthPanel::render() const {
  if (rows_.empty())
    throw InvalidInputError("depth panel has no row");
  for (const auto& r : rows_)
    if (r.cols != rows_.front().cols)
      throw InvalidInputError("depth panel rows differ in width");
  cv::Mat out;
  cv::vconcat(rows_, out);
  return out;
}

} // namespace msf
