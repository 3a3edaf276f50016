#include <msf/common/exceptions.h>
#include <msf/reconstruction/plane_distance.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace msf {

namespace {

/// The slope of 1/z along one axis at a pixel, per `k` pixels, from its neighbours at -2k, -k,
/// +k, +2k (0 = none): the central difference where the three middle samples lie on a line,
/// else the one-sided difference of a side whose three samples do (the pixel is next to an
/// edge or a fold, and that side is its own surface), else none (false).
bool slope(float i0, float m2, float m1, float p1, float p2, float tolerance, float& out) {
  if (m1 > 0.f && p1 > 0.f && std::abs(m1 + p1 - 2.f * i0) <= tolerance) {
    out = 0.5f * (p1 - m1);
    return true;
  }
  const float none = tolerance + 1.f;
  const float left = m2 > 0.f && m1 > 0.f ? std::abs(m2 + i0 - 2.f * m1) : none;
  const float right = p2 > 0.f && p1 > 0.f ? std::abs(i0 + p2 - 2.f * p1) : none;
  if (std::min(left, right) > tolerance)
    return false;
  out = left <= right ? i0 - m1 : p1 - i0;
  return true;
}

} // namespace

void planeDistanceScale(const cv::Mat& depth, const PinholeCamera& camera, const PlaneDistanceConfig& config,
                        cv::Mat& scale) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("planeDistanceScale: the depth image must be CV_32FC1");
  if (config.step_px < 1 || !(config.max_curvature >= 0.f) || !(config.min_scale > 0.f && config.min_scale <= 1.f))
    throw InvalidInputError("planeDistanceScale: need step_px >= 1, max_curvature >= 0 and 0 < min_scale <= 1");
  scale.create(depth.size(), CV_32FC1);
  const int k = config.step_px, width = depth.cols, height = depth.rows;
  const float gx_per_step = camera.fx / static_cast<float>(k);
  const float gy_per_step = camera.fy / static_cast<float>(k);
  const float curvature = config.max_curvature, min_scale = config.min_scale;
  auto inverse = [](float z) { return z > 0.f ? 1.f / z : 0.f; }; // NaN > 0 is false: none
  // 1/z at (u, v), 0 outside the image or without depth.
  auto at = [&](int u, int v) {
    return u >= 0 && u < width && v >= 0 && v < height ? inverse(depth.ptr<float>(v)[u]) : 0.f;
  };
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* d = depth.ptr<float>(v);
      float* s = scale.ptr<float>(v);
      const float yn = (static_cast<float>(v) - camera.cy) / camera.fy;
      for (int u = 0; u < width; ++u) {
        s[u] = 1.f;
        const float i0 = inverse(d[u]);
        if (!(i0 > 0.f))
          continue;
        // On a plane 1/z is affine in the pixel: a second difference is an edge or a fold.
        const float tolerance = curvature * i0;
        float sx, sy;
        if (!slope(i0, at(u - 2 * k, v), at(u - k, v), at(u + k, v), at(u + 2 * k, v), tolerance, sx) ||
            !slope(i0, at(u, v - 2 * k), at(u, v - k), at(u, v + k), at(u, v + 2 * k), tolerance, sy))
          continue;
        const float gx = sx * gx_per_step, gy = sy * gy_per_step;
        const float xn = (static_cast<float>(u) - camera.cx) / camera.fx;
        const float g0 = i0 - gx * xn - gy * yn;
        const float norm = std::sqrt(gx * gx + gy * gy + g0 * g0);
        s[u] = std::max(min_scale, i0 / norm);
      }
    }
  });
}

namespace {

/// The runs of one line of n samples of 1/z (stride apart; 0 = none): `largest[i]` becomes
/// the largest depth of sample i's run. A sample whose 1/z bends by more than `curvature` of
/// itself against its two neighbours ends the runs on either side (it is alone).
void lineRuns(const float* depth, std::ptrdiff_t stride, int n, float curvature, float* largest,
              std::ptrdiff_t out_stride, std::vector<char>& kink) {
  kink.assign(static_cast<std::size_t>(n), 0);
  auto inverse = [&](int i) { const float z = depth[i * stride]; return z > 0.f ? 1.f / z : 0.f; };
  for (int i = 1; i + 1 < n; ++i) {
    const float a = inverse(i - 1), b = inverse(i), c = inverse(i + 1);
    kink[static_cast<std::size_t>(i)] = a > 0.f && b > 0.f && c > 0.f && std::abs(a + c - 2.f * b) > curvature * b;
  }
  int begin = 0;
  while (begin < n) {
    if (!(depth[begin * stride] > 0.f)) {
      largest[begin * out_stride] = 0.f;
      ++begin;
      continue;
    }
    int end = begin + 1; // [begin, end): valid samples, no kink inside
    while (end < n && depth[end * stride] > 0.f && !kink[static_cast<std::size_t>(end)] &&
           !kink[static_cast<std::size_t>(end - 1)])
      ++end;
    float run_max = 0.f;
    for (int i = begin; i < end; ++i)
      run_max = std::max(run_max, depth[i * stride]);
    for (int i = begin; i < end; ++i)
      largest[i * out_stride] = run_max;
    begin = end;
  }
}

} // namespace

void smoothSurfaceExtent(const cv::Mat& depth, float max_curvature, cv::Mat& extent) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("smoothSurfaceExtent: the depth image must be CV_32FC1");
  const int width = depth.cols, height = depth.rows;
  extent.create(depth.size(), CV_32FC1);
  cv::Mat along_columns(depth.size(), CV_32FC1);
  const std::ptrdiff_t depth_step = static_cast<std::ptrdiff_t>(depth.step1());
  const std::ptrdiff_t out_step = static_cast<std::ptrdiff_t>(extent.step1());
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    std::vector<char> kink;
    for (int v = rows.start; v < rows.end; ++v)
      lineRuns(depth.ptr<float>(v), 1, width, max_curvature, extent.ptr<float>(v), 1, kink);
  });
  cv::parallel_for_(cv::Range(0, width), [&](const cv::Range& columns) {
    std::vector<char> kink;
    for (int u = columns.start; u < columns.end; ++u)
      lineRuns(depth.ptr<float>(0) + u, depth_step, height, max_curvature, along_columns.ptr<float>(0) + u, out_step,
               kink);
  });
  for (int v = 0; v < height; ++v) {
    const float* d = depth.ptr<float>(v);
    const float* c = along_columns.ptr<float>(v);
    float* e = extent.ptr<float>(v);
    for (int u = 0; u < width; ++u)
      e[u] = d[u] > 0.f ? std::max(e[u], c[u]) - d[u] : 0.f;
  }
}

} // namespace msf
