// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/range_image/depth_completion_filter.h>
#include <msf/range_image/distance_transform.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace msf {

namespace detail {
/// Sets the `distance` field of point types that have one.
template <typename PointT, typename = void>
struct HasDistance : std::false_type {};
template <typename PointT>
struct HasDistance<PointT, std::void_t<decltype(std::declval<PointT&>().distance)>> : std::true_type {};
} // namespace detail

template <typename PointT>
void DepthCompletionFilter<PointT>::keepIndexedReturns(cv::Mat& sparse) const {
  if (fake_indices_ || !indices_)
    return; // no setIndices: every point
  cv::Mat kept(sparse.size(), CV_32FC1, cv::Scalar(0));
  for (const auto i : *indices_) {
    if (i < 0 || static_cast<std::size_t>(i) >= sparse.total())
      throw InvalidInputError(filter_name_ + ": index " + std::to_string(i) + " is outside the cloud's " +
                              std::to_string(sparse.total()) + " points");
    kept.at<float>(static_cast<int>(i)) = sparse.at<float>(static_cast<int>(i));
  }
  sparse = kept;
}

template <typename PointT>
void DepthCompletionFilter<PointT>::applyFilter(PointCloud& output) {
  const PointCloud& in = *input_;
  if (!in.isOrganized() || in.empty())
    throw InvalidInputError(filter_name_ + ": expected an organized cloud (height > 1), got " +
                            std::to_string(in.width) + "x" + std::to_string(in.height) +
                            "; project the scan first (msf_project)");
  const PinholeCamera camera = camera_.valid() ? camera_ : estimatePinholeCamera(in);
  const int W = static_cast<int>(in.width), H = static_cast<int>(in.height);
  if (camera.width != W || camera.height != H)
    throw InvalidInputError(filter_name_ + ": cloud is " + std::to_string(W) + "x" + std::to_string(H) +
                            " but the camera is " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height));
  const double stripes = threads() > 0 ? threads() : -1; // at most that many threads at once

  sparse_.create(H, W, CV_32FC1);
  parallelFor(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      float* d = sparse_.ptr<float>(v);
      const PointT* p = &in[static_cast<std::size_t>(v) * W];
      for (int u = 0; u < W; ++u)
        d[u] = (std::isfinite(p[u].z) && p[u].z > 0.f) ? p[u].z : 0.f;
    }
  }, stripes);
  keepIndexedReturns(sparse_);
  completeDepth(sparse_, dense_);
  if (dense_.size() != sparse_.size() || dense_.type() != CV_32FC1)
    throw InvalidInputError(filter_name_ + ": completion returned an image of another size or type");
  distanceToSamples(sparse_, distance_, &nearest_, threads());

  output.resize(in.size());
  output.width = in.width;
  output.height = in.height;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inv_fx = 1.f / camera.fx, inv_fy = 1.f / camera.fy;
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, H), [&](const cv::Range& range) {
    bool all = true;
    for (int v = range.start; v < range.end; ++v) {
      const float* s = sparse_.ptr<float>(v);
      const float* z = dense_.ptr<float>(v);
      const float* dist = distance_.ptr<float>(v);
      const int* near = nearest_.ptr<int>(v);
      const std::size_t row = static_cast<std::size_t>(v) * W;
      const float ry = (static_cast<float>(v) - camera.cy) * inv_fy;
      for (int u = 0; u < W; ++u) {
        PointT& p = output[row + u];
        if (s[u] > 0.f && z[u] == s[u]) {
          p = in[row + u]; // a real return keeps its exact point
        } else if (z[u] > 0.f) {
          p = in[near[u] >= 0 ? static_cast<std::size_t>(near[u]) : row + u]; // other fields: nearest return's
          p.x = (static_cast<float>(u) - camera.cx) * inv_fx * z[u];
          p.y = ry * z[u];
          p.z = z[u];
        } else {
          p = in[row + u];
          p.x = p.y = p.z = nan;
          all = false;
        }
        if constexpr (detail::HasDistance<PointT>::value)
          p.distance = dist[u];
      }
    }
    if (!all)
      dense = false;
  }, stripes);
  output.is_dense = dense;
}

} // namespace msf
