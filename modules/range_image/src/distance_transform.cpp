// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/common/vector_clones.h>
#include <msf/range_image/distance_transform.h>

#include <opencv2/core/utility.hpp>
#ifdef __SSE2__
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace msf {

namespace {

/// Longest side handled, so that every real squared distance (at most 2 x 8192^2 = 2^27)
/// stays below kNone.
constexpr int kMaxSide = 1 << 13;
/// A squared distance meaning "no sample": above any real one, and a squared row distance
/// added to it stays below 2^31.
constexpr std::int32_t kNone = 1 << 28;

/// Pass 1 on one row: the squared distance along the row to its nearest sample (kNone
/// without one) and that sample's column (-1 without one); ties go to the left. Without
/// branches: where the samples are is unpredictable.
MSF_VECTOR_CLONES void rowDistances(const float* __restrict d, int W, std::int32_t* __restrict h2,
                                    std::int32_t* __restrict column) {
  constexpr std::int32_t kFar = 1 << 14; // beyond any width handled; (W + kFar)^2 < 2^31
  std::int32_t last = -kFar;
  for (int c = 0; c < W; ++c) {
    last = d[c] > 0.f ? c : last;
    column[c] = last;
  }
  std::int32_t next = W + kFar;
  for (int c = W - 1; c >= 0; --c) {
    next = d[c] > 0.f ? c : next;
    const std::int32_t left = c - column[c], right = next - c;
    column[c] = right < left ? next : column[c];
    const std::int32_t h = std::min(left, right);
    h2[c] = std::min(h * h, kNone);
  }
  if (column[0] < 0 || column[0] >= W) // no sample in the row
    std::fill(column, column + W, -1);
}

/// Squared distances to distances (+inf for kNone); the roots four at a time where SSE is
/// there (std::sqrt does not vectorize: errno).
MSF_VECTOR_CLONES void toDistances(const std::int32_t* __restrict d2, float* __restrict out, int n) {
  for (int c = 0; c < n; ++c)
    out[c] = d2[c] == kNone ? std::numeric_limits<float>::infinity() : static_cast<float>(d2[c]);
  int c = 0;
#ifdef __SSE2__
  for (; c + 4 <= n; c += 4)
    _mm_storeu_ps(out + c, _mm_sqrt_ps(_mm_loadu_ps(out + c)));
#endif
  for (; c < n; ++c)
    out[c] = std::sqrt(out[c]);
}

/// best = min(best, dy2 + h2) over one span of columns; returns the span's largest best.
MSF_VECTOR_CLONES std::int32_t relax(const std::int32_t* __restrict h2, std::int32_t dy2, std::int32_t* __restrict best,
                                     int n) {
  std::int32_t largest = 0;
  for (int c = 0; c < n; ++c) {
    best[c] = std::min(best[c], dy2 + h2[c]);
    largest = std::max(largest, best[c]);
  }
  return largest;
}

/// The same, also keeping the row-major index of the nearest sample (`row` * W + its column).
MSF_VECTOR_CLONES std::int32_t relaxNearest(const std::int32_t* __restrict h2, const std::int32_t* __restrict column,
                                            std::int32_t dy2, std::int32_t row_offset, std::int32_t* __restrict best,
                                            std::int32_t* __restrict nearest, int n) {
  std::int32_t largest = 0;
  for (int c = 0; c < n; ++c) {
    const std::int32_t candidate = dy2 + h2[c];
    const bool nearer = candidate < best[c];
    best[c] = nearer ? candidate : best[c];
    nearest[c] = nearer ? row_offset + column[c] : nearest[c];
    largest = std::max(largest, best[c]);
  }
  return largest;
}

} // namespace

void distanceToSamples(const cv::Mat& depth, cv::Mat& distance, cv::Mat* nearest, int threads) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("distanceToSamples: expected a non-empty CV_32FC1 depth image");
  const int H = depth.rows, W = depth.cols;
  if (H > kMaxSide || W > kMaxSide)
    throw InvalidInputError("distanceToSamples: the image is " + std::to_string(W) + "x" + std::to_string(H) +
                            ", more than " + std::to_string(kMaxSide) + " px on a side");
  const double stripes = threads > 0 ? threads : -1; // at most that many threads at once
  cv::Mat h2(H, W, CV_32SC1), column(H, W, CV_32SC1);
  std::vector<std::uint8_t> row_has_sample(static_cast<std::size_t>(H));
  distance.create(H, W, CV_32FC1);
  if (nearest)
    nearest->create(H, W, CV_32SC1);

  // Pass 1, rows: the distance along each row (LiDAR samples lie on rows).
  parallelFor(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      rowDistances(depth.ptr<float>(r), W, h2.ptr<std::int32_t>(r), column.ptr<std::int32_t>(r));
      row_has_sample[static_cast<std::size_t>(r)] = column.ptr<std::int32_t>(r)[0] >= 0;
    }
  }, stripes);

  // Pass 2: a pixel's squared distance is min over rows r' of (r - r')^2 + h2(r', c). Rows
  // are visited outwards from r, a span of columns at a time, until (r - r')^2 reaches the
  // span's largest distance so far: between the rings of a scan that is a few rows, where
  // the lower envelope of parabolas (exact in any case) branches on every column.
  constexpr int kSpan = 64;
  parallelFor(cv::Range(0, H), [&](const cv::Range& rows) {
    std::vector<std::int32_t> best(static_cast<std::size_t>(W));
    for (int r = rows.start; r < rows.end; ++r) {
      std::int32_t* b = best.data();
      int* idx = nearest ? nearest->ptr<int>(r) : nullptr;
      std::copy_n(h2.ptr<std::int32_t>(r), W, b);
      if (idx) {
        const std::int32_t* col = column.ptr<std::int32_t>(r);
        for (int c = 0; c < W; ++c)
          idx[c] = col[c] < 0 ? -1 : r * W + col[c];
      }
      for (int c0 = 0; c0 < W; c0 += kSpan) {
        const int n = std::min(kSpan, W - c0);
        std::int32_t largest = *std::max_element(b + c0, b + c0 + n);
        for (int dy = 1; largest > dy * dy && (r - dy >= 0 || r + dy < H); ++dy) {
          for (const int rr : {r - dy, r + dy}) {
            if (rr < 0 || rr >= H || !row_has_sample[static_cast<std::size_t>(rr)])
              continue;
            const std::int32_t* h = h2.ptr<std::int32_t>(rr) + c0;
            largest = idx ? relaxNearest(h, column.ptr<std::int32_t>(rr) + c0, dy * dy, rr * W, b + c0, idx + c0, n)
                          : relax(h, dy * dy, b + c0, n);
          }
        }
      }
      toDistances(b, distance.ptr<float>(r), W);
    }
  }, stripes);
}

} // namespace msf
