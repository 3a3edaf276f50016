// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/common/vector_clones.h>
#include <msf/fusion/fusion_model.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace msf {

namespace {
/// One row's disparities f B / z, as the largest (0 where none) and the smallest (+inf where none).
MSF_VECTOR_CLONES void disparityBounds(const float* __restrict__ z, int cols, float fB, float* __restrict__ largest,
                                       float* __restrict__ smallest) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int u = 0; u < cols; ++u) {
    const bool ok = (z[u] > 0.f) & (z[u] < inf);
    const float d = fB / (ok ? z[u] : 1.f);
    largest[u] = ok ? d : 0.f;
    smallest[u] = ok ? d : inf;
  }
}

void localDisparityExtremes(const cv::Mat& depth, double focal_baseline, int window, cv::Mat& largest,
                            cv::Mat& smallest) {
  const int rows = depth.rows, cols = depth.cols;
  const float fB = static_cast<float>(focal_baseline);
  // Missing pixels are 0 for the maximum and +inf for the minimum, so both see only values.
  largest.create(rows, cols, CV_32FC1);
  smallest.create(rows, cols, CV_32FC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v)
      disparityBounds(depth.ptr<float>(v), cols, fB, largest.ptr<float>(v), smallest.ptr<float>(v));
  });
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(window, window));
  cv::dilate(largest, largest, kernel);
  cv::erode(smallest, smallest, kernel);
}

void requireDepth(const cv::Mat& depth) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("LiDAR depth image must be CV_32FC1 (metres)");
}

/// |a + b - 2 c| where a, b and c are valid disparities (> 0), else 0.
inline float bendOf(float a, float b, float c) {
  return (a > 0.f) & (b > 0.f) & (c > 0.f) ? std::fabs(a + b - 2.f * c) : 0.f;
}
} // namespace

void localDisparityRange(const cv::Mat& depth, double focal_baseline, int window, cv::Mat& range) {
  requireDepth(depth);
  if (window < 1 || window % 2 == 0)
    throw InvalidInputError("local disparity range: window must be odd and >= 1");
  cv::Mat largest, smallest;
  localDisparityExtremes(depth, focal_baseline, window, largest, smallest);
  range.create(depth.rows, depth.cols, CV_32FC1);
  const float inf = std::numeric_limits<float>::infinity();
  for (int v = 0; v < depth.rows; ++v) {
    const float* __restrict__ h = largest.ptr<float>(v);
    const float* __restrict__ l = smallest.ptr<float>(v);
    float* __restrict__ out = range.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      out[u] = l[u] < inf ? h[u] - l[u] : 0.f;
  }
}

void localDisparityBend(const cv::Mat& depth, double focal_baseline, int step, cv::Mat& bend) {
  requireDepth(depth);
  if (step < 1)
    throw InvalidInputError("local disparity bend: step must be >= 1, not " + std::to_string(step));
  const int rows = depth.rows, cols = depth.cols, s = step;
  const float fB = static_cast<float>(focal_baseline);
  // The disparities first (0 = none), then the second differences of whole rows.
  cv::Mat d(rows, cols, CV_32FC1);
  bend.create(rows, cols, CV_32FC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& r) {
    std::vector<float> unused(static_cast<std::size_t>(cols));
    for (int v = r.start; v < r.end; ++v)
      disparityBounds(depth.ptr<float>(v), cols, fB, d.ptr<float>(v), unused.data());
  });
  parallelFor(cv::Range(0, rows), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v) {
      const float* __restrict__ c = d.ptr<float>(v);
      float* __restrict__ out = bend.ptr<float>(v);
      const bool column = v - s >= 0 && v + s < rows;
      const float* __restrict__ up = d.ptr<float>(column ? v - s : v);
      const float* __restrict__ down = d.ptr<float>(column ? v + s : v);
      for (int u = 0; u < cols; ++u)
        out[u] = column ? bendOf(up[u], down[u], c[u]) : 0.f;
      for (int u = s; u + s < cols; ++u)
        out[u] = std::max(out[u], bendOf(c[u - s], c[u + s], c[u]));
    }
  });
}

void lidarEdgeCue(const cv::Mat& lidar_depth, double focal_baseline, const DepthFusionConfig& config,
                  cv::Mat& cue) {
  if (config.lidar_edge_cue == LidarEdgeCue::Bend)
    localDisparityBend(lidar_depth, focal_baseline, std::max(1, config.lidar_range_window_px / 2), cue);
  else
    localDisparityRange(lidar_depth, focal_baseline, config.lidar_range_window_px, cue);
}

MSF_VECTOR_CLONES void fuseRow(const DepthFusionConfig& c, float focal_baseline, const LidarParallax& parallax,
                               const cv::Mat& lidar_depth, int v, const float* __restrict__ lidar_distance,
                               const float* __restrict__ lidar_edge, const float* __restrict__ z_stereo,
                               const float* __restrict__ stereo_confidence, float* __restrict__ fused_z,
                               float* __restrict__ fused_weight, float* __restrict__ fused_free_weight) {
  const int width = lidar_depth.cols, rows = lidar_depth.rows;
  const float* __restrict__ z_lidar = lidar_depth.ptr<float>(v);
  const DepthFusionConfig config = c; // a local copy: the compiler may keep it in registers
  if (config.method == FusionMethod::Paper) {
    // Eq. 6's weight is a trust in [0, 1]; the integrator averages with inverse variances
    // (m^-2): 1 is the best stereo match's at that depth.
    const float best_stereo = 1.f / (config.stereo_sigma_min_px * config.stereo_sigma_min_px);
    for (int u = 0; u < width; ++u) {
      FusionInputs in;
      in.z_lidar = z_lidar[u];
      in.lidar_distance = lidar_distance[u];
      in.z_stereo = z_stereo[u];
      in.stereo_confidence = stereo_confidence[u];
      const FusionResult r = fusePaper(in, config);
      fused_z[u] = r.z;
      fused_weight[u] = r.weight * depthWeight(r.z, best_stereo, focal_baseline);
    }
    std::copy_n(fused_weight, width, fused_free_weight);
    return;
  }
  float* __restrict__ free_weight = fused_free_weight;
  int candidates = 0; // pixels for the parallax check below
  for (int u = 0; u < width; ++u) {
    FusionInputs in;
    in.z_lidar = z_lidar[u];
    in.lidar_distance = lidar_distance[u];
    in.lidar_edge_px = lidar_edge[u];
    in.z_stereo = z_stereo[u];
    in.stereo_confidence = stereo_confidence[u];
    const FusionResult r = fuseUncertainty(in, config, focal_baseline);
    fused_z[u] = r.z;
    fused_weight[u] = r.weight;
    free_weight[u] = r.free_weight;
    candidates += (in.z_stereo > 0.f) & (r.z == in.z_lidar) & (in.z_stereo < in.z_lidar);
  }
  if (candidates == 0 || !(parallax.rows_per_px > 0.f))
    return;
  // The LiDAR kept although stereo saw a nearer surface: was it seen past a foreground edge?
  for (int u = 0; u < width; ++u) {
    if (!(z_stereo[u] > 0.f && fused_z[u] == z_lidar[u] && z_stereo[u] < z_lidar[u]))
      continue;
    const float s_S = stereoSigmaPx(stereo_confidence[u], config);
    const bool past = lidarSeesPastForeground(
        focal_baseline / z_lidar[u], focal_baseline / z_stereo[u], config.disagreement_k_sigma * s_S, focal_baseline,
        parallax.rows_per_px, parallax.max_rows,
        [&](int k) { return v + k < rows ? lidar_depth.ptr<float>(v + k)[u] : 0.f; });
    if (past) {
      fused_z[u] = z_stereo[u];
      fused_weight[u] = depthWeight(z_stereo[u], 1.f / (s_S * s_S), focal_baseline);
      free_weight[u] = fused_weight[u];
    }
  }
}

LidarParallax lidarParallax(const Calibration& calibration, const DepthFusionConfig& config) {
  LidarParallax parallax;
  // The LiDAR's origin in camera 0 (y points down): above the camera when y < 0.
  const double height = -calibration.T_cam0_velo.translation().y();
  const double baseline = calibration.baselineGrey();
  if (config.parallax_check && height > 0.0 && baseline > 0.0) {
    parallax.rows_per_px = static_cast<float>(height / baseline);
    parallax.max_rows = config.parallax_max_rows;
  }
  return parallax;
}

} // namespace msf
