// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/silhouette_thickness.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace msf {

namespace {

/// Thickness along each row of `depth` (its weight beside it), min'ed into `thickness`.
void rowThickness(const cv::Mat& depth, const cv::Mat& weight, float focal, float relative_jump, float sigmas,
                  cv::Mat& thickness) {
  const float sigmas2 = sigmas * sigmas;
  if (depth.cols == 0)
    return;
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
    const int n = depth.cols;
    std::vector<std::uint8_t> joined(static_cast<std::size_t>(n)); // pixel u and u + 1 on one object
    for (int v = rows.start; v < rows.end; ++v) {
      const float* z = depth.ptr<float>(v);
      const float* w = weight.ptr<float>(v);
      float* out = thickness.ptr<float>(v);
      // Within relative_jump of the nearer depth, or within `sigmas` of the larger sigma
      // (1 / sqrt of the lesser weight): |dz| <= sigmas / sqrt(w) as dz^2 w <= sigmas^2.
      const auto same = [&](int a, int b) {
        const float dz = z[a] - z[b];
        return (std::fabs(dz) <= relative_jump * std::min(z[a], z[b])) | (dz * dz * std::min(w[a], w[b]) <= sigmas2);
      };
      // Branch-free, so that it runs in vectors; the runs are then found with memchr.
      for (int u = 0; u + 1 < n; ++u)
        joined[static_cast<std::size_t>(u)] = static_cast<std::uint8_t>((z[u] > 0.f) & (z[u + 1] > 0.f) & same(u, u + 1));
      joined[static_cast<std::size_t>(n - 1)] = 0;
      // Past an end, across a hole of at most kSilhouetteMaxHole pixels (stereo leaves the
      // background an object hides from the other camera without a match), the next depth
      // sees farther.
      const auto bounded = [&](int end, int step) {
        for (int i = end + step, hole = 0; i >= 0 && i < n && hole <= kSilhouetteMaxHole; i += step, ++hole)
          if (z[i] > 0.f)
            return z[i] > z[end] && !same(i, end);
        return false;
      };
      for (int a = 0; a < n;) {
        if (!(z[a] > 0.f)) {
          ++a;
          continue;
        }
        const void* stop = std::memchr(joined.data() + a, 0, static_cast<std::size_t>(n - a));
        const int b = static_cast<int>(static_cast<const std::uint8_t*>(stop) - joined.data()); // joined[n - 1] is 0
        if (bounded(a, -1) && bounded(b, 1)) {
          const float width = static_cast<float>(b - a + 1) / focal; // metres per metre of depth
          for (int i = a; i <= b; ++i)
            out[i] = std::min(out[i], width * z[i]);
        }
        a = b + 1;
      }
    }
  });
}

} // namespace

void silhouetteThickness(const cv::Mat& depth, const cv::Mat& weight, const PinholeCamera& camera,
                         float relative_jump, float sigmas, cv::Mat& thickness) {
  if (depth.type() != CV_32FC1 || weight.type() != CV_32FC1 || depth.size() != weight.size())
    throw InvalidInputError("silhouetteThickness: depth and weight must be CV_32FC1 of one size");
  if (!(camera.fx > 0.0) || !(camera.fy > 0.0))
    throw InvalidInputError("silhouetteThickness: the camera's focal lengths must be > 0");
  if (!(relative_jump >= 0.f) || !(sigmas >= 0.f))
    throw InvalidInputError("silhouetteThickness: relative_jump and sigmas must be >= 0");
  thickness.create(depth.size(), CV_32FC1);
  thickness.setTo(std::numeric_limits<float>::infinity());
  rowThickness(depth, weight, static_cast<float>(camera.fx), relative_jump, sigmas, thickness);
  // Columns as the rows of the transposed images: contiguous, and the same code. The buffers
  // stay allocated from frame to frame (one set per calling thread).
  thread_local cv::Mat depth_t, weight_t, thickness_t, columns;
  cv::transpose(depth, depth_t);
  cv::transpose(weight, weight_t);
  thickness_t.create(depth.cols, depth.rows, CV_32FC1);
  thickness_t.setTo(std::numeric_limits<float>::infinity());
  rowThickness(depth_t, weight_t, static_cast<float>(camera.fy), relative_jump, sigmas, thickness_t);
  cv::transpose(thickness_t, columns);
  cv::min(thickness, columns, thickness);
}

} // namespace msf
