#include <msf/common/exceptions.h>
#include <msf/range_image/distance_transform.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace msf {

void distanceToSamples(const cv::Mat& depth, cv::Mat& distance, cv::Mat* nearest, int threads) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("distanceToSamples: expected a non-empty CV_32FC1 depth image");
  const int H = depth.rows, W = depth.cols;
  const int none = H + W + 1; // larger than any real vertical distance
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();

  // Pass 1, columns: vertical distance to the nearest sample of the column (and its row),
  // swept row by row so that the inner loop runs over contiguous memory.
  cv::Mat vertical(H, W, CV_32SC1), near_row;
  if (nearest)
    near_row.create(H, W, CV_32SC1);
  const int chunk = 64; // columns per task: whole cache lines per thread
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int c0 = 0; c0 < W; c0 += chunk) {
    const int c1 = std::min(W, c0 + chunk);
    for (int r = 0; r < H; ++r) {
      const float* d = depth.ptr<float>(r);
      int* g = vertical.ptr<int>(r);
      const int* up = r > 0 ? vertical.ptr<int>(r - 1) : nullptr;
      int* nr = nearest ? near_row.ptr<int>(r) : nullptr;
      const int* nr_up = nearest && r > 0 ? near_row.ptr<int>(r - 1) : nullptr;
      for (int c = c0; c < c1; ++c) {
        if (d[c] > 0.f) {
          g[c] = 0;
          if (nr)
            nr[c] = r;
        } else {
          g[c] = up ? std::min(up[c] + 1, none) : none;
          if (nr)
            nr[c] = nr_up ? nr_up[c] : -1;
        }
      }
    }
    for (int r = H - 2; r >= 0; --r) {
      int* g = vertical.ptr<int>(r);
      const int* down = vertical.ptr<int>(r + 1);
      int* nr = nearest ? near_row.ptr<int>(r) : nullptr;
      const int* nr_down = nearest ? near_row.ptr<int>(r + 1) : nullptr;
      for (int c = c0; c < c1; ++c)
        if (down[c] + 1 < g[c]) {
          g[c] = down[c] + 1;
          if (nr)
            nr[c] = nr_down[c];
        }
    }
  }

  // Pass 2, rows: lower envelope of the parabolas (x - q)^2 + g(q)^2.
  distance.create(H, W, CV_32FC1);
  if (nearest)
    nearest->create(H, W, CV_32SC1);
  const float inf = std::numeric_limits<float>::infinity();
#pragma omp parallel num_threads(nthreads)
  {
    std::vector<int> v(static_cast<std::size_t>(W));
    std::vector<float> z(static_cast<std::size_t>(W) + 1), f(static_cast<std::size_t>(W));
#pragma omp for schedule(static)
    for (int r = 0; r < H; ++r) {
      const int* g = vertical.ptr<int>(r);
      float* out = distance.ptr<float>(r);
      int k = -1;
      for (int q = 0; q < W; ++q) {
        if (g[q] >= none)
          continue; // no sample in this column
        f[q] = static_cast<float>(g[q]) * static_cast<float>(g[q]);
        const float fq = f[q] + static_cast<float>(q) * static_cast<float>(q);
        float s = -inf;
        while (k >= 0) {
          const int p = v[k];
          s = (fq - (f[p] + static_cast<float>(p) * static_cast<float>(p))) / static_cast<float>(2 * (q - p));
          if (s > z[k])
            break;
          --k;
        }
        ++k;
        v[k] = q;
        z[k] = k == 0 ? -inf : s;
        z[k + 1] = inf;
      }
      int* idx = nearest ? nearest->ptr<int>(r) : nullptr;
      if (k < 0) { // no sample anywhere
        std::fill(out, out + W, inf);
        if (idx)
          std::fill(idx, idx + W, -1);
        continue;
      }
      int j = 0;
      for (int q = 0; q < W; ++q) {
        while (z[j + 1] < static_cast<float>(q))
          ++j;
        const int p = v[j];
        const float dx = static_cast<float>(q - p);
        out[q] = std::sqrt(dx * dx + f[p]);
        if (idx)
          idx[q] = near_row.ptr<int>(r)[p] * W + p;
      }
    }
  }
}

} // namespace msf
