// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/hole_fill.h>

#include <cstdint>
#include <string>
#include <vector>

namespace msf {

namespace {

void requireOfDepthSize(const cv::Mat& image, int type, const cv::Size& size, const char* name) {
  if (!image.empty() && (image.type() != type || image.size() != size))
    throw InvalidInputError(std::string("fillSmallHoles: the ") + name + " is not " +
                            (type == CV_32FC1 ? "CV_32FC1" : "CV_8UC1") + " of the depth's size");
}

constexpr std::uint8_t kByRow = 255, kByColumn = 128;

/// Fills the holes of each row of `depth` in place from the nearest depth within `radius`
/// pixels on either side, unless an `excluded` pixel lies between; marks them kByRow in
/// `filled`. A pixel filled here is no source for another.
void fillRows(cv::Mat& depth, cv::Mat& filled, const cv::Mat& excluded, int radius) {
  std::vector<int> before(static_cast<std::size_t>(depth.cols));
  for (int v = 0; v < depth.rows; ++v) {
    float* z = depth.ptr<float>(v);
    std::uint8_t* mark = filled.ptr<std::uint8_t>(v);
    const std::uint8_t* skip = excluded.empty() ? nullptr : excluded.ptr<std::uint8_t>(v);
    // before[u]: the nearest pixel at or left of u with a depth, -1 when none or an excluded one is nearer.
    int last = -1;
    for (int u = 0; u < depth.cols; ++u) {
      if (skip && skip[u])
        last = -1;
      else if (z[u] > 0.f)
        last = u;
      before[static_cast<std::size_t>(u)] = last;
    }
    int next = -1; // the same on the right; the loop writes only pixels it has passed
    for (int u = depth.cols - 1; u >= 0; --u) {
      if (skip && skip[u]) {
        next = -1;
        continue;
      }
      if (z[u] > 0.f) {
        next = u;
        continue;
      }
      const int b = before[static_cast<std::size_t>(u)];
      const int left = b >= 0 ? u - b : radius + 1, right = next >= 0 ? next - u : radius + 1;
      if (left > radius && right > radius)
        continue;
      z[u] = left < right || (left == right && z[b] < z[next]) ? z[b] : z[next];
      mark[u] = kByRow;
    }
  }
}

/// The depth for hole (v, u) from the nearest pixel above or below within `radius` that has one
/// (measured or filled by the rows), not across an excluded pixel; 0 when there is none.
float nearestInColumn(const cv::Mat& depth, const cv::Mat& filled, const cv::Mat& excluded, int v, int u,
                      int radius) {
  float up = 0.f, down = 0.f;
  int up_gap = radius + 1, down_gap = radius + 1;
  for (int k = 1; k <= radius && v - k >= 0; ++k) {
    if (!excluded.empty() && excluded.at<std::uint8_t>(v - k, u))
      break;
    const float z = depth.at<float>(v - k, u);
    if (z > 0.f && filled.at<std::uint8_t>(v - k, u) != kByColumn) {
      up = z;
      up_gap = k;
      break;
    }
  }
  for (int k = 1; k <= radius && v + k < depth.rows && k <= up_gap; ++k) {
    if (!excluded.empty() && excluded.at<std::uint8_t>(v + k, u))
      break;
    const float z = depth.at<float>(v + k, u);
    if (z > 0.f && filled.at<std::uint8_t>(v + k, u) != kByColumn) {
      down = z;
      down_gap = k;
      break;
    }
  }
  if (up_gap > radius && down_gap > radius)
    return 0.f;
  return up_gap < down_gap || (up_gap == down_gap && up < down) ? up : down;
}

} // namespace

cv::Mat fillSmallHoles(cv::Mat& depth, cv::Mat& weight, cv::Mat& free_weight, const cv::Mat& excluded, int radius_px) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("fillSmallHoles: the depth is not CV_32FC1");
  requireOfDepthSize(weight, CV_32FC1, depth.size(), "weight");
  requireOfDepthSize(free_weight, CV_32FC1, depth.size(), "free-space weight");
  requireOfDepthSize(excluded, CV_8UC1, depth.size(), "excluded mask");
  cv::Mat filled(depth.size(), CV_8UC1, cv::Scalar(0));
  if (radius_px <= 0 || depth.empty())
    return filled;
  // Along the rows, then along the columns for the holes the rows left.
  fillRows(depth, filled, excluded, radius_px);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (z[u] > 0.f || filled.at<std::uint8_t>(v, u) || (!excluded.empty() && excluded.at<std::uint8_t>(v, u)))
        continue;
      const float nearest = nearestInColumn(depth, filled, excluded, v, u, radius_px);
      if (nearest > 0.f) {
        depth.at<float>(v, u) = nearest;
        filled.at<std::uint8_t>(v, u) = kByColumn;
      }
    }
  }
  filled.setTo(255, filled);
  if (!weight.empty())
    weight.setTo(0.f, filled);
  if (!free_weight.empty())
    free_weight.setTo(0.f, filled);
  return filled;
}

} // namespace msf
