// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/clear_sky.h>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

namespace msf {

namespace {

/// Sigmas by which a depth lies in front of its column's highest returns (a wall's depth) to be
/// in front of every wall: a wall's own pixels lie within three of their sigmas of it.
constexpr float kWallSigmas = 3.f;

/// The pixels of `open` (CV_8UC1, 255: open sky) whose depth lies in front of their column's
/// `wall_depth` (SkyMask::wallDepth; 0: no return, none is found) by more than kWallSigmas of
/// their sigma (`weight`, inverse variance; empty: by any amount): a blank wall that the mask takes
/// for sky lies at that depth, so such a depth is stereo's, carried over the sky from a pole beside it.
cv::Mat inFrontOfEveryWall(const cv::Mat& depth, const cv::Mat& weight, const std::vector<float>& wall_depth,
                           const cv::Mat& open) {
  cv::Mat in_front(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < depth.rows; ++v) {
    const std::uint8_t* sky = open.ptr<std::uint8_t>(v);
    const float* z = depth.ptr<float>(v);
    const float* w = weight.empty() ? nullptr : weight.ptr<float>(v);
    std::uint8_t* out = in_front.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!sky[u] || !(z[u] > 0.f))
        continue;
      const float wall = wall_depth[static_cast<std::size_t>(u)];
      const float margin = w && w[u] > 0.f ? kWallSigmas / std::sqrt(w[u]) : 0.f;
      out[u] = wall > 0.f && z[u] < wall - margin ? 255 : 0;
    }
  }
  return in_front;
}

} // namespace

cv::Mat withholdClearSky(const SkyMask& sky, const cv::Mat& image, const cv::Mat& grey, const cv::Mat& returns,
                         cv::Mat& depth, cv::Mat& weight, cv::Mat& free_weight, cv::Mat* clear_sky) {
  const std::initializer_list<cv::Mat*> images = {&depth, &weight, &free_weight};
  for (const cv::Mat* values : images) // all checked before any is changed
    if (!values->empty() && (values->type() != CV_32FC1 || values->size() != image.size()))
      throw InvalidInputError("withholdClearSky: the depth and weights must be CV_32FC1 of the sky image's size");
  const bool own_grey = !grey.empty() && grey.data != image.data;
  if (own_grey && (grey.type() != CV_8UC1 || grey.size() != image.size()))
    throw InvalidInputError("withholdClearSky: camera 0's grey image must be CV_8UC1 of the sky image's size");
  cv::Mat open = sky.computeWithoutBorder(image, returns);
  // clearSky tests each pixel alone: the bordered mask's clear pixels are these within it.
  const cv::Mat clear = sky.clearSky(image, open);
  cv::Mat withheld = clear.clone();
  cv::Mat open_in_both = open.clone(); // a pixel both cameras see as blank sky
  sky.takeBorder(open);
  if (own_grey) { // within the border, where the parallax moves an edge, camera 0's own sky decides
    const cv::Mat open_in_grey = sky.computeWithoutBorder(grey, returns);
    withheld = (withheld & (open | open_in_grey)) | sky.clearSky(grey, open_in_grey) |
               sky.clippedOutline(grey, returns, open_in_grey);
    open_in_both &= open_in_grey;
  }
  if (clear_sky)
    *clear_sky = clear & open & open_in_both;
  if (!depth.empty())
    withheld |= inFrontOfEveryWall(depth, weight, sky.wallDepth(returns), open_in_both);
  for (cv::Mat* values : images)
    if (!values->empty())
      values->setTo(0.f, withheld);
  return open | withheld;
}

const cv::Mat& skyImage(const cv::Mat& colour, const cv::Mat& grey, const cv::Size& size) {
  return colour.type() == CV_8UC3 && colour.size() == size ? colour : grey;
}

} // namespace msf
