// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/message_text.h>
#include <msf/fusion/sky_mask.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace msf {

namespace {

/// OpenCV's 8-bit hue (degrees / 2) from cyan to violet: a clear sky's.
constexpr double kBlueHueMin = 85.0, kBlueHueMax = 135.0;
/// Side of the window of the texture's standard deviation.
constexpr int kTextureWindow = 5;
/// Rows within which returns lie on one ring (KITTI's rings lie 5-6 pixels apart up there).
constexpr int kOneRingRows = 3;

void checkImage(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw InvalidInputError("sky mask: the image must be CV_8UC1 grey or CV_8UC3 BGR");
}

void checkMask(const cv::Mat& sky, const cv::Mat& image) {
  if (sky.type() != CV_8UC1 || sky.size() != image.size())
    throw InvalidInputError("sky mask: the mask must be CV_8UC1 of the image's " + sizeText(image) + ", not " +
                            sizeText(sky) + " of type " + std::to_string(sky.type()));
}

/// The image, its LiDAR returns (CV_32FC1 of its size) and the settings a mask is found with.
void checkInputs(const cv::Mat& image, const cv::Mat& returns, int column_window, int border) {
  checkImage(image);
  if (returns.type() != CV_32FC1 || returns.size() != image.size())
    throw InvalidInputError("sky mask: the LiDAR returns must be CV_32FC1 of the image's " + sizeText(image) +
                            ", not " + sizeText(returns) + " of type " + std::to_string(returns.type()));
  if (column_window < 0 || border < 0)
    throw ConfigError("sky mask: the column window and the border must be >= 0, not " +
                      std::to_string(column_window) + " and " + std::to_string(border));
}

} // namespace

cv::Mat SkyMask::skyLike(const cv::Mat& image) const {
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  cv::Mat grey_f, mean, mean_sq;
  grey.convertTo(grey_f, CV_32F);
  const cv::Size window(kTextureWindow, kTextureWindow);
  cv::boxFilter(grey_f, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  cv::boxFilter(grey_f.mul(grey_f), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  const cv::Mat variance = mean_sq - mean.mul(mean);
  cv::Mat sky = (grey >= min_brightness_) & (variance <= max_texture_ * max_texture_);
  if (image.channels() == 3) {
    cv::Mat hsv, grey_white, blue;
    cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
    cv::inRange(hsv, cv::Scalar(0, 0, 0), cv::Scalar(180, max_saturation_, 255), grey_white);
    cv::inRange(hsv, cv::Scalar(kBlueHueMin, 0, 0), cv::Scalar(kBlueHueMax, 255, 255), blue);
    sky &= grey_white | blue;
  }
  return sky;
}

namespace {

/// The pixels (255) of `image` (CV_8UC1 or CV_8UC3) with a channel at `level` or above.
cv::Mat clippedPixels(const cv::Mat& image, double level) {
  if (image.channels() == 1)
    return image >= level;
  cv::Mat channel[3];
  cv::split(image, channel);
  return cv::max(cv::max(channel[0], channel[1]), channel[2]) >= level;
}

} // namespace

cv::Mat SkyMask::clearSky(const cv::Mat& image, const cv::Mat& sky) const {
  checkImage(image);
  checkMask(sky, image);
  cv::Mat clear(sky.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect area = cv::boundingRect(sky);
  if (area.empty())
    return clear;
  const cv::Mat pixels = image(area);
  cv::Mat out = clippedPixels(pixels, clipped_level_);
  if (pixels.channels() == 3) {
    cv::Mat hsv, blue;
    cv::cvtColor(pixels, hsv, cv::COLOR_BGR2HSV);
    cv::inRange(hsv, cv::Scalar(kBlueHueMin, max_saturation_ + 1, 0), cv::Scalar(kBlueHueMax, 255, 255), blue);
    out |= blue;
  }
  cv::Mat clear_area = clear(area);
  cv::bitwise_and(out, sky(area), clear_area);
  return clear;
}

cv::Mat SkyMask::clippedOutline(const cv::Mat& image, const cv::Mat& returns, const cv::Mat& sky) const {
  checkInputs(image, returns, column_window_, border_);
  checkMask(sky, image);
  cv::Mat passable = clippedPixels(image, clipped_level_);
  const std::vector<TopReturn> top = topReturns(returns);
  for (int u = 0; u < passable.cols; ++u) // step 2: nothing below the LiDAR's highest returns
    passable.col(u).rowRange(std::min(top[static_cast<std::size_t>(u)].row, passable.rows), passable.rows).setTo(0);
  passable |= sky;
  cv::Mat reached = sky.clone();
  for (int step = 0; step < border_; ++step) {
    cv::dilate(reached, reached, cv::Mat());
    reached &= passable;
  }
  return reached & ~sky;
}

namespace {

/// The highest return among `first`..`last` (its row; the image's height: none) and the nearest on
/// its ring: a pixel's row decides the highest among returns at one elevation, and a far one must
/// not stand for a near wall beside it.
template <class It>
auto nearestOnHighestRing(It first, It last) {
  auto t = *std::min_element(first, last, [](const auto& a, const auto& b) { return a.row < b.row; });
  for (auto it = first; it != last; ++it)
    if (it->row <= t.row + kOneRingRows && it->depth > 0.f)
      t.depth = std::min(t.depth, it->depth);
  return t;
}

} // namespace

std::vector<SkyMask::TopReturn> SkyMask::highestReturns(const cv::Mat& returns) {
  if (returns.type() != CV_32FC1)
    throw InvalidInputError("sky mask: the LiDAR returns must be CV_32FC1, not of type " +
                            std::to_string(returns.type()));
  std::vector<TopReturn> highest(static_cast<std::size_t>(returns.cols), TopReturn{returns.rows, 0.f});
  for (int v = returns.rows - 1; v >= 0; --v) {
    const float* z = returns.ptr<float>(v);
    for (int u = 0; u < returns.cols; ++u)
      if (z[u] > 0.f)
        highest[static_cast<std::size_t>(u)] = TopReturn{v, z[u]};
  }
  return highest;
}

std::vector<SkyMask::TopReturn> SkyMask::topReturns(const cv::Mat& returns) const {
  const std::vector<TopReturn> highest = highestReturns(returns);
  std::vector<TopReturn> top(highest.size());
  for (int u = 0; u < returns.cols; ++u) {
    const auto first = highest.begin() + std::max(0, u - column_window_);
    const auto last = highest.begin() + std::min(returns.cols, u + column_window_ + 1);
    top[static_cast<std::size_t>(u)] = nearestOnHighestRing(first, last);
  }
  return top;
}

std::vector<float> SkyMask::topReturnDepth(const cv::Mat& returns) const {
  const std::vector<TopReturn> top = topReturns(returns);
  std::vector<float> depth(top.size());
  std::transform(top.begin(), top.end(), depth.begin(), [](const TopReturn& t) { return t.depth; });
  return depth;
}

std::vector<float> SkyMask::wallDepth(const cv::Mat& returns) const {
  const std::vector<TopReturn> highest = highestReturns(returns);
  std::vector<float> depth(highest.size());
  for (int u = 0; u < returns.cols; ++u) {
    const auto first = highest.begin() + std::max(0, u - column_window_);
    const auto last = highest.begin() + std::min(returns.cols, u + column_window_ + 1);
    const auto at = highest.begin() + u;
    const float left = nearestOnHighestRing(first, at + 1).depth;
    const float right = nearestOnHighestRing(at, last).depth;
    depth[static_cast<std::size_t>(u)] = std::max(left, right); // a side with none (0): the other's
  }
  return depth;
}

cv::Mat SkyMask::compute(const cv::Mat& image, const cv::Mat& returns) const {
  cv::Mat mask = computeWithoutBorder(image, returns);
  takeBorder(mask);
  return mask;
}

cv::Mat SkyMask::computeWithoutBorder(const cv::Mat& image, const cv::Mat& returns) const {
  checkInputs(image, returns, column_window_, border_);
  const std::vector<TopReturn> top = topReturns(returns);
  // Only the rows above the lowest column's highest return can be sky: the steps run on them,
  // with the rows that the texture window reaches below.
  int lowest = 0;
  for (const TopReturn& t : top)
    lowest = std::max(lowest, t.row);
  const int band_rows = std::min(image.rows, lowest + kTextureWindow / 2 + 1);
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(0));
  cv::Mat band = mask.rowRange(0, band_rows);
  skyLike(image.rowRange(0, band_rows)).copyTo(band);
  for (int v = 0; v < band.rows; ++v) {
    std::uint8_t* s = band.ptr<std::uint8_t>(v);
    for (int u = 0; u < band.cols; ++u)
      if (v >= top[static_cast<std::size_t>(u)].row)
        s[u] = 0;
  }
  keepOpenToTheTop(band);
  return mask;
}

void SkyMask::keepOpenToTheTop(cv::Mat& sky) {
  cv::Mat labels;
  const int count = cv::connectedComponents(sky, labels, 8, CV_32S);
  std::vector<std::uint8_t> open(static_cast<std::size_t>(count), 0);
  const int* top_row = labels.ptr<int>(0);
  for (int u = 0; u < labels.cols; ++u)
    open[static_cast<std::size_t>(top_row[u])] = top_row[u] != 0;
  for (int v = 0; v < sky.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    std::uint8_t* s = sky.ptr<std::uint8_t>(v);
    for (int u = 0; u < sky.cols; ++u)
      s[u] = open[static_cast<std::size_t>(l[u])] ? 255 : 0;
  }
}

void SkyMask::takeBorder(cv::Mat& mask) const {
  if (border_ > 0)
    cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * border_ + 1, 2 * border_ + 1)),
              cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
}

cv::Mat skyDepthImage(const cv::Mat& sky, const std::vector<float>& column_depth, const cv::Mat& clear_sky) {
  if (sky.type() != CV_8UC1)
    throw InvalidInputError("sky depth: the sky mask must be CV_8UC1, not of type " + std::to_string(sky.type()));
  if (!clear_sky.empty() && (clear_sky.type() != CV_8UC1 || clear_sky.size() != sky.size()))
    throw InvalidInputError("sky depth: the clear sky must be a CV_8UC1 mask of the sky's " + std::to_string(sky.cols) +
                            "x" + std::to_string(sky.rows) + ", not " + std::to_string(clear_sky.cols) + "x" +
                            std::to_string(clear_sky.rows) + " of type " + std::to_string(clear_sky.type()));
  if (column_depth.size() != static_cast<std::size_t>(sky.cols))
    throw InvalidInputError("sky depth: the column depths must be one per image column (" + std::to_string(sky.cols) +
                            "), not " + std::to_string(column_depth.size()));
  constexpr float kNotSky = std::numeric_limits<float>::quiet_NaN();
  constexpr float kUnbounded = std::numeric_limits<float>::infinity();
  cv::Mat sky_depth(sky.size(), CV_32FC1);
  for (int v = 0; v < sky.rows; ++v) {
    const std::uint8_t* open = sky.ptr<std::uint8_t>(v);
    const std::uint8_t* clear = clear_sky.empty() ? nullptr : clear_sky.ptr<std::uint8_t>(v);
    float* depth = sky_depth.ptr<float>(v);
    for (int u = 0; u < sky.cols; ++u) {
      const float bound = column_depth[static_cast<std::size_t>(u)];
      const bool unbounded = (clear && clear[u] != 0) || !(bound > 0.f);
      depth[u] = open[u] == 0 ? kNotSky : unbounded ? kUnbounded : bound;
    }
  }
  return sky_depth;
}

} // namespace msf
