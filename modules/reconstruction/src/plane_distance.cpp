// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/plane_distance.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
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

/// 4 floats in SIMD lanes (GCC and Clang vector extensions: SSE2 on x86-64, NEON on ARM);
/// comparisons give 0 or -1 per lane. Code written for T = float or Float4 runs either way.
using Float4 = float __attribute__((vector_size(16)));

template <typename T>
T load(const float* p) {
  T x;
  std::memcpy(&x, p, sizeof x);
  return x;
}
template <typename T>
void store(float* p, T x) {
  std::memcpy(p, &x, sizeof x);
}

/// 1/z of every pixel, 0 where there is no depth (NaN included), inside a border of `pad`
/// zeros: the neighbours of a pixel near the image's edge are read without a bounds test, and
/// each depth is inverted once rather than by every neighbour that reads it.
cv::Mat paddedInverse(const cv::Mat& depth, int pad) {
  cv::Mat inverse(depth.rows + 2 * pad, depth.cols + 2 * pad, CV_32FC1, cv::Scalar(0.f));
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* d = depth.ptr<float>(v);
      float* out = inverse.ptr<float>(v + pad) + pad;
      for (int u = 0; u < depth.cols; ++u)
        out[u] = d[u] > 0.f ? 1.f / d[u] : 0.f;
    }
  });
  return inverse;
}

} // namespace

void planeDistanceScale(const cv::Mat& depth, const PinholeCamera& camera, const PlaneDistanceConfig& config,
                        cv::Mat& scale) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("planeDistanceScale: the depth image must be CV_32FC1");
  if (config.step_px < 1 || !(config.max_curvature >= 0.f) || !(config.min_scale > 0.f && config.min_scale <= 1.f))
    throw InvalidInputError("planeDistanceScale: need step_px >= 1, max_curvature >= 0 and 0 < min_scale <= 1");
  scale.create(depth.size(), CV_32FC1);
  const int k = config.step_px, width = depth.cols;
  const float gx_per_step = camera.fx / static_cast<float>(k);
  const float gy_per_step = camera.fy / static_cast<float>(k);
  const float curvature = config.max_curvature, min_scale = config.min_scale;
  const int pad = 2 * k;
  const cv::Mat inverse = paddedInverse(depth, pad);
  const std::ptrdiff_t down = static_cast<std::ptrdiff_t>(inverse.step1()) * k; // k rows
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* i = inverse.ptr<float>(v + pad) + pad; // 1/z at (u, v) is i[u]
      float* s = scale.ptr<float>(v);
      const float yn = (static_cast<float>(v) - camera.cy) / camera.fy;
      for (int u = 0; u < width; ++u) {
        s[u] = 1.f;
        const float* c = i + u;
        const float i0 = *c;
        if (!(i0 > 0.f))
          continue;
        // On a plane 1/z is affine in the pixel: a second difference is an edge or a fold.
        const float tolerance = curvature * i0;
        float sx, sy;
        if (!slope(i0, c[-2 * k], c[-k], c[k], c[2 * k], tolerance, sx) ||
            !slope(i0, c[-2 * down], c[-down], c[down], c[2 * down], tolerance, sy))
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

// A run is a stretch of pixels with depth along a row or a column; it ends where 1/z bends by
// more than max_curvature of itself between three consecutive pixels (a kink: such a pixel is
// alone). With a border of one zero, the image's first and last pixels are no kink. Each line
// is walked forwards keeping the largest depth of the run so far (stored negated where the
// pixel joins the run before it), then backwards handing every pixel its run's largest, that
// of the run's last pixel. Without branches, in SIMD lanes where the lines are columns: noisy
// stereo's runs end at random. T is float or Float4.

/// 1 where the middle of three 1/z samples is a kink, else 0.
template <typename T>
T kink(float max_curvature, T a, T b, T c) {
  const T bend = a + c - 2.f * b, limit = max_curvature * b;
  return (a > 0.f) & (b > 0.f) & (c > 0.f) & ((bend > limit) | (-bend > limit)) ? T{} + 1.f : T{};
}

/// One step forwards: a pixel of depth z after one of depth `before` joins its run when both
/// have depth and neither is a kink; `run` becomes the run's largest so far.
template <typename T>
T forward(T before, T z, T kink_before, T kink_here, T& run) {
  const auto join = (before > 0.f) & (z > 0.f) & (kink_before == 0.f) & (kink_here == 0.f);
  const T larger = run > z ? run : z;
  run = join ? larger : (z > 0.f ? z : T{});
  return join ? -run : run;
}

/// Each pixel's run's largest depth along its row, into `extent`.
void rowRunLargest(const cv::Mat& depth, const cv::Mat& inverse, float max_curvature, cv::Mat& extent) {
  const int width = depth.cols;
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
    std::vector<float> kinks(static_cast<std::size_t>(width));
    for (int v = rows.start; v < rows.end; ++v) {
      const float* d = depth.ptr<float>(v);
      const float* i = inverse.ptr<float>(v + 1) + 1;
      float* e = extent.ptr<float>(v);
      const int whole = width - width % 4;
      for (int u = 0; u < whole; u += 4)
        store(&kinks[static_cast<std::size_t>(u)],
              kink(max_curvature, load<Float4>(i + u - 1), load<Float4>(i + u), load<Float4>(i + u + 1)));
      for (int u = whole; u < width; ++u)
        kinks[static_cast<std::size_t>(u)] = kink(max_curvature, i[u - 1], i[u], i[u + 1]);
      float run = 0.f;
      e[0] = forward(0.f, d[0], 0.f, kinks[0], run);
      for (int u = 1; u < width; ++u)
        e[u] = forward(d[u - 1], d[u], kinks[static_cast<std::size_t>(u) - 1], kinks[static_cast<std::size_t>(u)], run);
      for (int u = width - 1; u > 0; --u) {
        const float signed_run = e[u], before = std::abs(e[u - 1]);
        e[u] = run;
        run = signed_run < 0.f ? run : before;
      }
      e[0] = run;
    }
  });
}

/// Each pixel's run's largest depth along its column, the larger of it and the row's (in
/// `extent`) less the pixel's depth into `extent`. A strip of columns at a time, row after row
/// (contiguous reads).
void columnRunLargest(const cv::Mat& depth, const cv::Mat& inverse, float max_curvature, cv::Mat& extent) {
  const int width = depth.cols, height = depth.rows;
  cv::Mat down(depth.size(), CV_32FC1);
  constexpr int kStrip = 64;
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(inverse.step1());
  parallelFor(cv::Range(0, (width + kStrip - 1) / kStrip), [&](const cv::Range& strips) {
    const int u0 = strips.start * kStrip, n = std::min(width, strips.end * kStrip) - u0;
    // Per column of the strip: the run's largest so far, whether the pixel above is a kink.
    std::vector<float> run(static_cast<std::size_t>(n)), kink_above(run.size(), 0.f), none(run.size(), 0.f);
    // Columns k.. of the strip, T = Float4 for 4 columns at once or float for one.
    auto walk_down = [&](auto lanes, int v, int k) {
      using T = decltype(lanes);
      const float* i = inverse.ptr<float>(v + 1) + 1 + u0 + k;
      const T here = kink(max_curvature, load<T>(i - row), load<T>(i), load<T>(i + row));
      T r = load<T>(&run[k]);
      const float* above = v > 0 ? depth.ptr<float>(v - 1) + u0 + k : &none[k];
      store(down.ptr<float>(v) + u0 + k,
            forward(load<T>(above), load<T>(depth.ptr<float>(v) + u0 + k), load<T>(&kink_above[k]), here, r));
      store(&run[k], r);
      store(&kink_above[k], here);
    };
    // `run` then holds each column's last run's largest.
    auto walk_up = [&](auto lanes, int v, int k) {
      using T = decltype(lanes);
      const T z = load<T>(depth.ptr<float>(v) + u0 + k), row_largest = load<T>(extent.ptr<float>(v) + u0 + k);
      const T r = load<T>(&run[k]);
      store(extent.ptr<float>(v) + u0 + k, z > 0.f ? (row_largest > r ? row_largest : r) - z : T{});
      if (v > 0) {
        const T signed_run = load<T>(down.ptr<float>(v) + u0 + k), a = load<T>(down.ptr<float>(v - 1) + u0 + k);
        store(&run[k], signed_run < 0.f ? r : (a < 0.f ? -a : a));
      }
    };
    const int whole = n - n % 4;
    for (int v = 0; v < height; ++v) {
      for (int k = 0; k < whole; k += 4)
        walk_down(Float4(), v, k);
      for (int k = whole; k < n; ++k)
        walk_down(0.f, v, k);
    }
    for (int v = height - 1; v >= 0; --v) {
      for (int k = 0; k < whole; k += 4)
        walk_up(Float4(), v, k);
      for (int k = whole; k < n; ++k)
        walk_up(0.f, v, k);
    }
  });
}

} // namespace

void smoothSurfaceExtent(const cv::Mat& depth, float max_curvature, cv::Mat& extent) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("smoothSurfaceExtent: the depth image must be CV_32FC1");
  extent.create(depth.size(), CV_32FC1);
  const cv::Mat inverse = paddedInverse(depth, 1);
  rowRunLargest(depth, inverse, max_curvature, extent);
  columnRunLargest(depth, inverse, max_curvature, extent);
}

} // namespace msf
