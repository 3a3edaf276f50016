#include <msf/common/exceptions.h>
#include <msf/range_image/distance_transform.h>

#include <omp.h>
#ifdef __SSE2__
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace msf {

namespace {

/// In place, four at a time where SSE is there (std::sqrt does not vectorize: errno).
void squareRoots(float* x, int n) {
  int i = 0;
#ifdef __SSE2__
  for (; i + 4 <= n; i += 4)
    _mm_storeu_ps(x + i, _mm_sqrt_ps(_mm_loadu_ps(x + i)));
#endif
  for (; i < n; ++i)
    x[i] = std::sqrt(x[i]);
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define MSF_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define MSF_VECTOR_CLONES
#endif

/// Pass 1 downwards, one row: 0 on a sample, else one more than the row above (or none).
MSF_VECTOR_CLONES void sweepDown(const float* __restrict d, const int* __restrict up, int* __restrict g, int n,
                                 int none) {
  for (int c = 0; c < n; ++c) {
    const int above = up ? std::min(up[c] + 1, none) : none;
    g[c] = d[c] > 0.f ? 0 : above;
  }
}

/// Pass 1 upwards, one row: the nearer of its own and the row below's plus one.
MSF_VECTOR_CLONES void sweepUp(const int* __restrict down, int* __restrict g, int n) {
  for (int c = 0; c < n; ++c)
    g[c] = std::min(g[c], down[c] + 1);
}

/// Work space of one thread for envelopeRow.
struct Envelope {
  std::vector<int> v;               ///< columns of the parabolas of the lower envelope
  std::vector<std::int64_t> h;      ///< their g^2 + q^2
  std::vector<std::int64_t> num;    ///< left end of each parabola's interval: num / den
  std::vector<std::int64_t> den;
  explicit Envelope(int W) : v(W), h(W), num(W + 1), den(W + 1) {}
};

/// Pass 2 on one row: the lower envelope of the parabolas (x - q)^2 + g(q)^2
/// (Felzenszwalb and Huttenlocher 2012) gives the squared distance and the nearest
/// column. Intersections are kept as exact fractions of integers, so there is no
/// division and no rounding. Columns with g >= none have no sample and no parabola.
void envelopeRow(const int* g, int W, int none, float* d2, int* column, Envelope& envelope) {
  // Intersection of parabolas p < q: s = (h_q - h_p) / (2 (q - p)).
  int* ev = envelope.v.data();
  std::int64_t* eh = envelope.h.data();
  std::int64_t* num = envelope.num.data();
  std::int64_t* den = envelope.den.data();
  int k = -1;
  for (int q = 0; q < W; ++q) {
    if (g[q] >= none)
      continue;
    const std::int64_t hq = static_cast<std::int64_t>(g[q]) * g[q] + static_cast<std::int64_t>(q) * q;
    std::int64_t sn = 0, sd = 1;
    while (k >= 0) {
      sn = hq - eh[k];
      sd = 2 * static_cast<std::int64_t>(q - ev[k]);
      // s > z[k], with z[0] = -inf.
      if (k == 0 || sn * den[k] > num[k] * sd)
        break;
      --k;
    }
    ++k;
    ev[k] = q;
    eh[k] = hq;
    num[k] = sn; // unused for k == 0 (-inf)
    den[k] = sd;
  }
  if (k < 0) {
    std::fill(d2, d2 + W, std::numeric_limits<float>::infinity());
    std::fill(column, column + W, -1);
    return;
  }
  int j = 0;
  for (int q = 0; q < W; ++q) {
    // Next parabola once its interval starts at or before q: num / den <= q.
    while (j < k && num[j + 1] <= static_cast<std::int64_t>(q) * den[j + 1])
      ++j;
    const int p = ev[j];
    const std::int64_t dx = q - p;
    d2[q] = static_cast<float>(dx * dx + eh[j] - static_cast<std::int64_t>(p) * p);
    column[q] = p;
  }
}

} // namespace

void distanceToSamples(const cv::Mat& depth, cv::Mat& distance, cv::Mat* nearest, int threads) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("distanceToSamples: expected a non-empty CV_32FC1 depth image");
  const int H = depth.rows, W = depth.cols;
  const int none = H + W + 1; // more than any vertical distance: a column without sample
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  cv::Mat vertical(H, W, CV_32SC1), near_row;
  if (nearest) {
    near_row.create(H, W, CV_32SC1);
    nearest->create(H, W, CV_32SC1);
  }
  distance.create(H, W, CV_32FC1);

#pragma omp parallel num_threads(nthreads)
  {
    // Pass 1, columns: vertical distance to the nearest sample of the column (and its row),
    // swept down then up a band of columns so that the inner loops are contiguous.
    const int bands = omp_get_num_threads();
#pragma omp for schedule(static)
    for (int b = 0; b < bands; ++b) {
      const int c0 = std::min(W, (W * b / bands + 15) / 16 * 16);
      const int c1 = b + 1 == bands ? W : std::min(W, (W * (b + 1) / bands + 15) / 16 * 16);
      for (int r = 0; r < H; ++r) {
        const float* d = depth.ptr<float>(r);
        int* g = vertical.ptr<int>(r);
        sweepDown(d + c0, r > 0 ? vertical.ptr<int>(r - 1) + c0 : nullptr, g + c0, c1 - c0, none);
        if (nearest) {
          int* nr = near_row.ptr<int>(r);
          const int* nr_up = near_row.ptr<int>(r > 0 ? r - 1 : 0);
          for (int c = c0; c < c1; ++c)
            nr[c] = d[c] > 0.f ? r : (r > 0 ? nr_up[c] : -1);
        }
      }
      for (int r = H - 2; r >= 0; --r) {
        int* g = vertical.ptr<int>(r);
        const int* down = vertical.ptr<int>(r + 1);
        if (nearest) {
          int* nr = near_row.ptr<int>(r);
          const int* nr_down = near_row.ptr<int>(r + 1);
          for (int c = c0; c < c1; ++c)
            if (down[c] + 1 < g[c]) {
              g[c] = down[c] + 1;
              nr[c] = nr_down[c];
            }
        } else {
          sweepUp(down + c0, g + c0, c1 - c0);
        }
      }
    }

    // Pass 2, rows.
    Envelope envelope(W);
    std::vector<int> column(static_cast<std::size_t>(W));
#pragma omp for schedule(static)
    for (int r = 0; r < H; ++r) {
      float* out = distance.ptr<float>(r);
      envelopeRow(vertical.ptr<int>(r), W, none, out, column.data(), envelope);
      squareRoots(out, W);
      if (nearest) {
        const int* nr = near_row.ptr<int>(r);
        int* idx = nearest->ptr<int>(r);
        for (int q = 0; q < W; ++q)
          idx[q] = column[q] < 0 ? -1 : nr[column[q]] * W + column[q];
      }
    }
  }
}

} // namespace msf
