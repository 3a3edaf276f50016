// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/vector_clones.h>
#include <msf/fusion/edge_support.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace msf {

namespace {
// Disparities in 1/8 px steps in 16 bits: OpenCV's morphology then moves half the bytes of
// floats (the step is memory-bound), the window search needs no division, and 1/16 px of
// rounding does not matter against a tolerance and a jump of pixels. The depth a pixel takes
// is its return's own.
constexpr float kSteps = 8.f;
constexpr std::uint16_t kNone = std::numeric_limits<std::uint16_t>::max();

// The loops below are written so that GCC vectorises them (selects of values, no branch;
// the file is compiled with -fno-trapping-math).

/// One row of real returns' disparities in steps: `high` holds 0 and `low` kNone where there
/// is none.
MSF_VECTOR_CLONES void returnSteps(const float* __restrict__ z, const float* __restrict__ distance, int cols, float fB,
                                   std::uint16_t* __restrict__ high, std::uint16_t* __restrict__ low) {
  const float inf = std::numeric_limits<float>::infinity(), largest = kNone - 1;
  for (int u = 0; u < cols; ++u) {
    const float z_real = distance[u] == 0.f ? z[u] : 0.f;
    const bool real = (z_real > 0.f) & (z_real < inf);
    const float steps = fB * kSteps / (real ? z_real : 1.f) + 0.5f;
    const auto q = static_cast<std::uint16_t>(steps < largest ? steps : largest);
    high[u] = real ? q : std::uint16_t{0};
    low[u] = real ? q : kNone;
  }
}

/// 1 where the fused disparity lies at an edge of the returns (the window's extremes more
/// than `jump` apart), between the extremes and farther than `tolerance` from both; 0
/// elsewhere. All in
/// steps. Returns how many there are.
MSF_VECTOR_CLONES int edgeCandidates(const float* __restrict__ z, const std::uint16_t* __restrict__ high,
                                      const std::uint16_t* __restrict__ low, int cols, float fB, float jump,
                                      float tolerance, std::int32_t* __restrict__ candidate) {
  int count = 0;
  for (int u = 0; u < cols; ++u) {
    const float d = fB * kSteps / (z[u] > 0.f ? z[u] : 1.f);
    const float h = high[u], l = low[u];
    // No fused depth, or no return in the window (0 - kNone): never > jump.
    const float span = z[u] > 0.f ? h - l : 0.f;
    // Strictly between the extremes: a value nearer than every return (a pole the LiDAR
    // missed) or beyond all of them is no blend of the two surfaces.
    candidate[u] = (span > jump) & (d - l > tolerance) & (h - d > tolerance);
    count += candidate[u];
  }
  return count;
}
} // namespace

void supportAtDepthEdges(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, float focal_baseline,
                         const DepthFusionConfig& config, cv::Mat& fused_depth, EdgeSupportBuffers& buffers) {
  const int rows = lidar_depth.rows, cols = lidar_depth.cols;
  const float fB = focal_baseline;
  if (lidar_distance.empty() && (buffers.zeros.cols != cols || buffers.zeros.type() != CV_32FC1))
    buffers.zeros = cv::Mat(1, cols, CV_32FC1, cv::Scalar(0)); // every LiDAR depth is a real return
  // 1. The real returns' disparities, and their extremes over the window around each pixel.
  buffers.returns.create(rows, cols, CV_16UC1);
  buffers.smallest.create(rows, cols, CV_16UC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v)
      returnSteps(lidar_depth.ptr<float>(v),
                  lidar_distance.empty() ? buffers.zeros.ptr<float>(0) : lidar_distance.ptr<float>(v), cols, fB,
                  buffers.returns.ptr<std::uint16_t>(v), buffers.smallest.ptr<std::uint16_t>(v));
  });
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {config.edge_window_cols, config.edge_window_rows});
  parallelFor(cv::Range(0, 2), [&](const cv::Range& range) { // the two at once
    for (int k = range.start; k < range.end; ++k)
      if (k == 0)
        cv::dilate(buffers.returns, buffers.largest, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
      else
        cv::erode(buffers.smallest, buffers.smallest, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(kNone));
  });
  // 2. The pixels between the two surfaces of an edge (a few per thousand) take the depth of
  //    the return in the window nearest their disparity, unless one is within the tolerance.
  const int half_rows = config.edge_window_rows / 2, half_cols = config.edge_window_cols / 2;
  const float jump = config.edge_jump_px * kSteps, tolerance = config.edge_tolerance_px * kSteps;
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<std::int32_t> candidate(static_cast<std::size_t>(cols));
    for (int v = range.start; v < range.end; ++v) {
      float* z = fused_depth.ptr<float>(v);
      if (!edgeCandidates(z, buffers.largest.ptr<std::uint16_t>(v), buffers.smallest.ptr<std::uint16_t>(v), cols, fB,
                          jump, tolerance, candidate.data()))
        continue;
      for (int u = 0; u < cols; ++u) {
        if (!candidate[static_cast<std::size_t>(u)])
          continue;
        const int d = static_cast<int>(fB * kSteps / z[u] + 0.5f);
        int gap = std::numeric_limits<int>::max(), best_row = 0, best_col = 0;
        for (int r = std::max(0, v - half_rows); r <= std::min(rows - 1, v + half_rows); ++r) {
          const std::uint16_t* returns = buffers.returns.ptr<std::uint16_t>(r); // 0: none
          for (int c = std::max(0, u - half_cols); c <= std::min(cols - 1, u + half_cols); ++c) {
            const int g = returns[c] ? std::abs(returns[c] - d) : std::numeric_limits<int>::max();
            best_row = g < gap ? r : best_row;
            best_col = g < gap ? c : best_col;
            gap = g < gap ? g : gap;
          }
        }
        if (static_cast<float>(gap) > tolerance)
          z[u] = lidar_depth.at<float>(best_row, best_col);
      }
    }
  });
}

} // namespace msf
