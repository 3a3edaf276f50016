#include <msf/common/exceptions.h>
#include <msf/stereo/median_blur_3x3.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace msf {

namespace {

// Rows per task: enough to amortise a task, small enough to balance two busy cores.
constexpr int kRowsPerTask = 16;

// Plain loops the compiler vectorises; cloned for AVX2 (16 lanes) and the SSE2 baseline.
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define MSF_MEDIAN_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define MSF_MEDIAN_CLONES
#endif

/// One output row from its three source rows (above, here, below; already clamped at the
/// image's top and bottom). `lo`, `mid`, `hi` hold width + 2 values: each column sorted,
/// with the first and the last column repeated at either end.
MSF_MEDIAN_CLONES
void medianRow(const std::int16_t* __restrict a, const std::int16_t* __restrict b, const std::int16_t* __restrict c,
               int width, std::int16_t* __restrict lo, std::int16_t* __restrict mid, std::int16_t* __restrict hi,
               std::int16_t* __restrict out) {
  for (int u = 0; u < width; ++u) {
    const std::int16_t x = a[u], y = b[u], z = c[u];
    const std::int16_t min_xy = std::min(x, y), max_xy = std::max(x, y);
    lo[u + 1] = std::min(min_xy, z);
    hi[u + 1] = std::max(max_xy, z);
    mid[u + 1] = std::max(min_xy, std::min(max_xy, z));
  }
  lo[0] = lo[1];
  mid[0] = mid[1];
  hi[0] = hi[1];
  lo[width + 1] = lo[width];
  mid[width + 1] = mid[width];
  hi[width + 1] = hi[width];
  // The median of the 3x3 window is the median of: the largest column minimum, the median
  // of the column medians and the smallest column maximum.
  for (int u = 0; u < width; ++u) {
    const std::int16_t lo_max = std::max(std::max(lo[u], lo[u + 1]), lo[u + 2]);
    const std::int16_t hi_min = std::min(std::min(hi[u], hi[u + 1]), hi[u + 2]);
    const std::int16_t m0 = mid[u], m1 = mid[u + 1], m2 = mid[u + 2];
    const std::int16_t mid_med = std::max(std::min(m0, m1), std::min(std::max(m0, m1), m2));
    out[u] = std::max(std::min(lo_max, mid_med), std::min(std::max(lo_max, mid_med), hi_min));
  }
}

} // namespace

void medianBlur3x3(const cv::Mat& src, cv::Mat& dst) {
  if (src.empty() || src.type() != CV_16SC1)
    throw InvalidInputError("medianBlur3x3: the image must be a non-empty CV_16SC1 image");
  if (dst.data == src.data && !dst.empty())
    throw InvalidInputError("medianBlur3x3: the output must not share the input's data");
  dst.create(src.size(), CV_16SC1);
  const int rows = src.rows, cols = src.cols;
  const int tasks = (rows + kRowsPerTask - 1) / kRowsPerTask;
  cv::parallel_for_(cv::Range(0, tasks), [&](const cv::Range& range) {
    std::vector<std::int16_t> sorted(3 * static_cast<std::size_t>(cols + 2));
    std::int16_t* lo = sorted.data();
    std::int16_t* mid = lo + cols + 2;
    std::int16_t* hi = mid + cols + 2;
    const int end = std::min(range.end * kRowsPerTask, rows);
    for (int v = range.start * kRowsPerTask; v < end; ++v)
      medianRow(src.ptr<std::int16_t>(std::max(v - 1, 0)), src.ptr<std::int16_t>(v),
                src.ptr<std::int16_t>(std::min(v + 1, rows - 1)), cols, lo, mid, hi, dst.ptr<std::int16_t>(v));
  });
}

} // namespace msf
