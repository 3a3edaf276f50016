// AVX2 kernel of SemiGlobalMatcher: OpenCV's StereoSGBM (MODE_SGBM_3WAY) cost, aggregation
// and winner selection, 16 disparities per instruction. Only the functions marked MSF_AVX2
// use AVX2, so this file builds for any x86-64 and the caller picks it at run time.
//
// Per row, with r the block radius and D the number of disparities:
//  1. pixel cost: Birchfield-Tomasi dissimilarity of the Sobel-x prefiltered rows (clipped
//     at the prefilter cap) plus a quarter of that of the raw rows, as 8-bit;
//  2. block cost: a running sum over 2r+1 rows per column and disparity (the pixel costs of
//     the row entering and of the row leaving are recomputed rather than stored, so the
//     buffers of a strip stay within a core's L2 cache), then a sliding sum over 2r+1 columns;
//  3. paths: left-to-right and top-to-bottom in one pass, right-to-left in a second pass that
//     also picks the disparity (uniqueness, parabolic sub-pixel, pseudo left-right check).
#include "semi_global_kernel.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MSF_SGM_X86 1
#endif

#include <cstring>

namespace msf::detail {

namespace {

constexpr std::size_t kAlign = 64;
constexpr std::size_t alignUp(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

/// Byte offsets of the buffers of one strip inside its workspace.
struct Layout {
  int width1{0};       ///< columns that can be matched: [min_x, min_x + width1)
  int min_x{0};
  int num_disparities{0};
  int ring{0};         ///< prepared rows kept (2r + 2: the row entering and the one leaving)
  std::size_t column_sums{0}, top{0}, sums{0}, top_minima{0}, box{0}, left{0}, right{0}, total{0};
  std::size_t prep{0}, prep_rows{0}, disp2{0}, disp2_cost{0}, bytes{0};

  Layout(int width, int min_disparity, int num_disparities_, int block_radius) : num_disparities(num_disparities_) {
    const int max_disparity = min_disparity + num_disparities;
    min_x = max_disparity > 0 ? max_disparity : 0;
    const int max_x = width + (min_disparity < 0 ? min_disparity : 0);
    width1 = max_x > min_x ? max_x - min_x : 0;
    ring = 2 * block_radius + 2;
    const std::size_t volume_row = alignUp(sizeof(std::int16_t) * static_cast<std::size_t>(width1) * num_disparities);
    const std::size_t line = alignUp(sizeof(std::int16_t) * static_cast<std::size_t>(num_disparities));
    std::size_t at = 0;
    const auto take = [&at](std::size_t n) {
      const std::size_t here = at;
      at += alignUp(n);
      return here;
    };
    column_sums = take(volume_row);
    top = take(volume_row);
    sums = take(volume_row);
    top_minima = take(sizeof(std::uint16_t) * static_cast<std::size_t>(width1));
    box = take(line);
    left = take(line);
    right = take(line);
    total = take(line);
    prep = take(static_cast<std::size_t>(ring) * kPrepArrays * kSgmPrepStride);
    prep_rows = take(sizeof(int) * static_cast<std::size_t>(ring));
    disp2 = take(sizeof(std::int16_t) * static_cast<std::size_t>(width));
    disp2_cost = take(sizeof(std::int16_t) * static_cast<std::size_t>(width));
    bytes = at + kAlign; // the caller's pointer is aligned here
  }

  /// Per prepared row: for each image, the prefiltered row and its Birchfield-Tomasi minimum
  /// and maximum, then the raw row and its minimum and maximum; the right image reversed.
  static constexpr int kPrepArrays = 12;
};

} // namespace

std::size_t sgmWorkspaceBytes(int width, int min_disparity, int num_disparities, int block_radius) {
  return Layout(width, min_disparity, num_disparities, block_radius).bytes;
}

#ifdef MSF_SGM_X86

bool sgmAvx2Available() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

// noinline: one symbol per stage in a profile; each is called once per row or more rarely.
#define MSF_AVX2 __attribute__((target("avx2"), noinline))
#define MSF_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

namespace {

/// Sobel-x response clipped to [-cap, cap] and shifted to [0, 2 cap], and the raw row, of
/// one image row; the first and last columns hold `cap` in both (as OpenCV's prefilter).
MSF_AVX2 void prefilterRow(const std::uint8_t* up, const std::uint8_t* row, const std::uint8_t* down, int width, int cap,
                           std::uint8_t* sobel, std::uint8_t* raw) {
  for (int x = 1; x < width - 1; ++x) {
    int g = (row[x + 1] - row[x - 1]) * 2 + up[x + 1] - up[x - 1] + down[x + 1] - down[x - 1];
    g = g < -cap ? -cap : (g > cap ? cap : g);
    sobel[x] = static_cast<std::uint8_t>(g + cap);
    raw[x] = row[x];
  }
  sobel[0] = sobel[width - 1] = raw[0] = raw[width - 1] = static_cast<std::uint8_t>(cap);
}

/// Minimum and maximum of a pixel and its two half-pixel neighbours (Birchfield-Tomasi).
MSF_AVX2 void halfPixelRange(const std::uint8_t* a, int width, std::uint8_t* low, std::uint8_t* high) {
  const auto range = [&](int x, int l, int r) {
    const int v = a[x];
    int lo = v < l ? v : l, hi = v > l ? v : l;
    lo = lo < r ? lo : r;
    hi = hi > r ? hi : r;
    low[x] = static_cast<std::uint8_t>(lo);
    high[x] = static_cast<std::uint8_t>(hi);
  };
  if (width == 1) {
    range(0, a[0], a[0]);
    return;
  }
  range(0, a[0], (a[0] + a[1]) / 2);
  for (int x = 1; x < width - 1; ++x)
    range(x, (a[x] + a[x - 1]) / 2, (a[x] + a[x + 1]) / 2);
  range(width - 1, (a[width - 1] + a[width - 2]) / 2, a[width - 1]);
}

MSF_AVX2 void reverseRow(std::uint8_t* a, int width) {
  for (int i = 0, j = width - 1; i < j; ++i, --j) {
    const std::uint8_t t = a[i];
    a[i] = a[j];
    a[j] = t;
  }
}

struct Strip {
  const SgmStrip& s;
  Layout layout;
  std::uint8_t* base;

  explicit Strip(const SgmStrip& strip)
      : s(strip), layout(strip.width, strip.min_disparity, strip.num_disparities, strip.block_radius),
        base(reinterpret_cast<std::uint8_t*>((reinterpret_cast<std::uintptr_t>(strip.workspace) + kAlign - 1) &
                                             ~static_cast<std::uintptr_t>(kAlign - 1))) {}

  template <typename T>
  T* at(std::size_t offset) const {
    return reinterpret_cast<T*>(base + offset);
  }

  /// The prepared arrays of image row `y` (clamped), computing them if not in the ring.
  MSF_AVX2 const std::uint8_t* preparedRow(int y) const {
    y = y < 0 ? 0 : (y >= s.height ? s.height - 1 : y);
    const int slot_index = y % layout.ring;
    int* tags = at<int>(layout.prep_rows);
    std::uint8_t* slot = at<std::uint8_t>(layout.prep) + static_cast<std::size_t>(slot_index) * Layout::kPrepArrays * kSgmPrepStride;
    if (tags[slot_index] == y)
      return slot;
    tags[slot_index] = y;
    constexpr int stride = kSgmPrepStride;
    for (int array = 0; array < Layout::kPrepArrays; ++array) // defined padding for the wide loads
      std::memset(slot + static_cast<std::size_t>(array) * stride + s.width, 0, kSgmPrepStride - kSgmMaxWidth);
    for (int image = 0; image < 2; ++image) {
      const std::uint8_t* first = image == 0 ? s.left : s.right;
      const std::size_t step = image == 0 ? s.left_step : s.right_step;
      const std::uint8_t* row = first + static_cast<std::size_t>(y) * step;
      const std::uint8_t* up = y > 0 ? row - step : row;
      const std::uint8_t* down = y < s.height - 1 ? row + step : row;
      std::uint8_t* a = slot + static_cast<std::size_t>(image) * 6 * stride;
      prefilterRow(up, row, down, s.width, s.prefilter_cap, a, a + 3 * stride);
      if (image == 1) { // right rows reversed: disparities d, d+1, ... are then ascending addresses
        reverseRow(a, s.width);
        reverseRow(a + 3 * stride, s.width);
      }
      halfPixelRange(a, s.width, a + stride, a + 2 * stride);
      halfPixelRange(a + 3 * stride, s.width, a + 4 * stride, a + 5 * stride);
    }
    return slot;
  }
};

/// 8-bit Birchfield-Tomasi dissimilarity of the left value u (with its half-pixel range
/// [u0, u1]) against 32 right values at v (ranges at v0, v1).
MSF_AVX2_INLINE __m256i dissimilarity(__m256i u, __m256i u0, __m256i u1, const std::uint8_t* v, const std::uint8_t* v0,
                                      const std::uint8_t* v1) {
  const __m256i vv = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v));
  const __m256i vv0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v0));
  const __m256i vv1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v1));
  const __m256i c0 = _mm256_max_epu8(_mm256_subs_epu8(u, vv1), _mm256_subs_epu8(vv0, u));
  const __m256i c1 = _mm256_max_epu8(_mm256_subs_epu8(vv, u1), _mm256_subs_epu8(u0, vv));
  return _mm256_min_epu8(c0, c1);
}

/// Pixel costs of left column x against 32 consecutive disparities of one prepared row.
struct PixelCost {
  __m256i su, su0, su1, ru, ru0, ru1;
  const std::uint8_t* right; // prefiltered right row (reversed) at the first disparity
  /// A constant, so that the six arrays are addressed from one register.
  static constexpr int stride = kSgmPrepStride;

  MSF_AVX2_INLINE PixelCost(const std::uint8_t* prepared, int x, int reversed_first) {
    su = _mm256_set1_epi8(static_cast<char>(prepared[x]));
    su0 = _mm256_set1_epi8(static_cast<char>(prepared[stride + x]));
    su1 = _mm256_set1_epi8(static_cast<char>(prepared[2 * stride + x]));
    ru = _mm256_set1_epi8(static_cast<char>(prepared[3 * stride + x]));
    ru0 = _mm256_set1_epi8(static_cast<char>(prepared[4 * stride + x]));
    ru1 = _mm256_set1_epi8(static_cast<char>(prepared[5 * stride + x]));
    right = prepared + 6 * stride + reversed_first;
  }

  /// Costs of disparities first + d .. first + d + 31: prefiltered + raw / 4 (<= 189).
  MSF_AVX2_INLINE __m256i operator()(int d) const {
    const std::uint8_t* r = right + d;
    const __m256i sobel = dissimilarity(su, su0, su1, r, r + stride, r + 2 * stride);
    const __m256i raw = dissimilarity(ru, ru0, ru1, r + 3 * stride, r + 4 * stride, r + 5 * stride);
    const __m256i quarter = _mm256_and_si256(_mm256_srli_epi16(raw, 2), _mm256_set1_epi8(0x3F));
    return _mm256_adds_epu8(sobel, quarter);
  }
};

/// column_sums of column xi += costs of row `add` - costs of row `sub` (kSubtract) for every
/// disparity, widened to 16 bits in disparity order.
template <bool kSubtract>
MSF_AVX2_INLINE void updateColumn(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, int xi) {
  const Layout& layout = strip.layout;
  const int D = layout.num_disparities;
  const int x = xi + layout.min_x;
  const int reversed_first = strip.s.width - 1 - x + strip.s.min_disparity;
  const PixelCost cost_add(add, x, reversed_first);
  std::int16_t* column = strip.at<std::int16_t>(layout.column_sums) + static_cast<std::size_t>(xi) * D;
  if constexpr (kSubtract) {
    // (+1, -1) byte pairs: maddubs turns interleaved (add, sub) bytes into add - sub.
    const __m256i plus_minus = _mm256_set1_epi16(static_cast<short>(0xFF01));
    const PixelCost cost_sub(sub, x, reversed_first);
#pragma GCC unroll 4
    for (int d = 0; d < D; d += 32) {
      // Lanes reordered so that the in-lane unpacks give disparities d..d+15, d+16..d+31.
      const __m256i a = _mm256_permute4x64_epi64(cost_add(d), 0xD8);
      const __m256i b = _mm256_permute4x64_epi64(cost_sub(d), 0xD8);
      const __m256i low = _mm256_maddubs_epi16(_mm256_unpacklo_epi8(a, b), plus_minus);
      __m256i* p = reinterpret_cast<__m256i*>(column + d);
      _mm256_storeu_si256(p, _mm256_add_epi16(_mm256_loadu_si256(p), low));
      if (d + 16 < D) {
        const __m256i high = _mm256_maddubs_epi16(_mm256_unpackhi_epi8(a, b), plus_minus);
        _mm256_storeu_si256(p + 1, _mm256_add_epi16(_mm256_loadu_si256(p + 1), high));
      }
    }
  } else {
    for (int d = 0; d < D; d += 32) {
      const __m256i a = cost_add(d);
      __m256i* p = reinterpret_cast<__m256i*>(column + d);
      const __m256i low = _mm256_cvtepu8_epi16(_mm256_castsi256_si128(a));
      _mm256_storeu_si256(p, _mm256_add_epi16(_mm256_loadu_si256(p), low));
      if (d + 16 < D) {
        const __m256i high = _mm256_cvtepu8_epi16(_mm256_extracti128_si256(a, 1));
        _mm256_storeu_si256(p + 1, _mm256_add_epi16(_mm256_loadu_si256(p + 1), high));
      }
    }
  }
}

/// column_sums += costs of row `add` for every column: the strip's first block of rows.
MSF_AVX2 void addRowToColumnSums(const Strip& strip, const std::uint8_t* add) {
  for (int xi = 0; xi < strip.layout.width1; ++xi)
    updateColumn<false>(strip, add, nullptr, xi);
}

/// Smallest of 16 non-negative 16-bit values.
MSF_AVX2_INLINE int horizontalMin(__m256i v) {
  const __m128i m = _mm_min_epu16(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  return _mm_cvtsi128_si32(_mm_minpos_epu16(m)) & 0xFFFF;
}

/// Hirschmueller's recursion for 16 disparities: cost + min(L(d), L(d-1) + P1, L(d+1) + P1,
/// min L + P2) - min L, with `below` = L(d-1) and `above` = L(d+1) of the previous pixel.
MSF_AVX2_INLINE __m256i pathStep(__m256i cost, __m256i below, __m256i above, __m256i same, __m256i p1,
                                 __m256i previous_min_p2, __m256i previous_min) {
  const __m256i m = _mm256_min_epi16(_mm256_adds_epi16(_mm256_min_epi16(below, above), p1),
                                     _mm256_min_epi16(same, previous_min_p2));
  return _mm256_adds_epi16(cost, _mm256_sub_epi16(m, previous_min));
}

/// Neighbours one disparity down and up of `current` (16 lanes), given the vectors before
/// (`cross` = its high half and current's low half) and after (`cross_next`).
MSF_AVX2_INLINE __m256i disparityBelow(__m256i current, __m256i cross) { return _mm256_alignr_epi8(current, cross, 14); }
MSF_AVX2_INLINE __m256i disparityAbove(__m256i current, __m256i cross_next) {
  return _mm256_alignr_epi8(cross_next, current, 2);
}

/// One path's state while its D disparities are swept 16 at a time, updating `costs` in place.
struct PathSweep {
  std::int16_t* costs;
  int count; // vectors of 16
  __m256i current, cross, minimum, previous_min, previous_min_p2;

  MSF_AVX2_INLINE PathSweep(std::int16_t* costs_, int count_, int previous, int p2) : costs(costs_), count(count_) {
    const __m256i top = _mm256_set1_epi16(0x7FFF);
    current = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(costs));
    cross = _mm256_permute2x128_si256(top, current, 0x21);
    minimum = top;
    previous_min = _mm256_set1_epi16(static_cast<short>(previous));
    const int with_p2 = previous + p2;
    previous_min_p2 = _mm256_set1_epi16(static_cast<short>(with_p2 > 0x7FFF ? 0x7FFF : with_p2));
  }

  /// New costs of vector k from `cost`, stored in place; returns them.
  MSF_AVX2_INLINE __m256i step(int k, __m256i cost, __m256i p1) {
    const __m256i next = k + 1 < count ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(costs + 16 * (k + 1)))
                                       : _mm256_set1_epi16(0x7FFF);
    const __m256i cross_next = _mm256_permute2x128_si256(current, next, 0x21);
    const __m256i result = pathStep(cost, disparityBelow(current, cross), disparityAbove(current, cross_next), current,
                                    p1, previous_min_p2, previous_min);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(costs + 16 * k), result);
    minimum = _mm256_min_epi16(minimum, result);
    current = next;
    cross = cross_next;
    return result;
  }
};

MSF_AVX2_INLINE __m256i load16(const std::int16_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
MSF_AVX2_INLINE void store16(std::int16_t* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

/// box = sum over columns first - r .. first + r (clamped to the matched columns) of the column sums.
MSF_AVX2 void startBox(const Strip& strip, int first, int direction) {
  const Layout& layout = strip.layout;
  const int D = layout.num_disparities, r = strip.s.block_radius, last = layout.width1 - 1;
  const std::int16_t* sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  const __m256i edge_weight = _mm256_set1_epi16(static_cast<short>(r + 1));
  for (int d = 0; d < D; d += 16) {
    __m256i acc = _mm256_mullo_epi16(load16(sums + static_cast<std::size_t>(first) * D + d), edge_weight);
    for (int j = 1; j <= r; ++j) {
      int xi = first + direction * j;
      xi = xi < 0 ? 0 : (xi > last ? last : xi);
      acc = _mm256_adds_epi16(acc, load16(sums + static_cast<std::size_t>(xi) * D + d));
    }
    store16(box + d, acc);
  }
}

/// Left-to-right and top-to-bottom paths of one row; their sum goes to `sums` (output rows).
/// K (vectors of 16 disparities) is a compile-time constant where forwardPass is
/// instantiated for it, so that the sweep over disparities unrolls.
/// With `add` (and `sub`), each column's sums first move down one row: the block row
/// entering is `add`, the one leaving `sub` (fused here so the sums are read once).
template <bool kOutput>
MSF_AVX2_INLINE void forwardPassFor(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, const int K) {
  const Layout& layout = strip.layout;
  const int D = 16 * K, r = strip.s.block_radius, last = layout.width1 - 1;
  const std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  std::int16_t* left = strip.at<std::int16_t>(layout.left);
  std::int16_t* top = strip.at<std::int16_t>(layout.top);
  std::int16_t* sums = strip.at<std::int16_t>(layout.sums);
  std::uint16_t* top_minima = strip.at<std::uint16_t>(layout.top_minima);
  const __m256i p1 = _mm256_set1_epi16(static_cast<short>(strip.s.p1));
  const int p2 = strip.s.p2;
  if (add)
    for (int xi = 0; xi <= r && xi <= last; ++xi)
      updateColumn<true>(strip, add, sub, xi);
  startBox(strip, 0, 1);
  std::memset(left, 0, sizeof(std::int16_t) * static_cast<std::size_t>(D)); // the path starts with L = C
  int left_min = 0;
  for (int xi = 0; xi <= last; ++xi) {
    // Columns move down in blocks of 8 ahead of the paths: two tight loops instead of one
    // that runs out of registers, while the block's sums are still in L1.
    if (add && xi > 0 && (xi - 1) % 8 == 0)
      for (int c = xi + r; c < xi + r + 8 && c <= last; ++c)
        updateColumn<true>(strip, add, sub, c);
    const std::int16_t* entering = column_sums + static_cast<std::size_t>(xi + r < last ? xi + r : last) * D;
    const std::int16_t* leaving = column_sums + static_cast<std::size_t>(xi - r - 1 > 0 ? xi - r - 1 : 0) * D;
    // At the first column the box is already complete: add and remove nothing.
    const __m256i first = _mm256_set1_epi16(xi > 0 ? -1 : 0);
    std::int16_t* top_x = top + static_cast<std::size_t>(xi) * D;
    PathSweep top_path(top_x, K, top_minima[xi], p2);
    PathSweep left_path(left, K, left_min, p2);
    std::int16_t* sums_x = sums + static_cast<std::size_t>(xi) * D;
#pragma GCC unroll 8
    for (int k = 0; k < K; ++k) {
      const __m256i change = _mm256_sub_epi16(load16(entering + 16 * k), load16(leaving + 16 * k));
      const __m256i cost = _mm256_add_epi16(load16(box + 16 * k), _mm256_and_si256(change, first));
      store16(box + 16 * k, cost);
      const __m256i t = top_path.step(k, cost, p1);
      if constexpr (kOutput)
        store16(sums_x + 16 * k, _mm256_adds_epi16(left_path.step(k, cost, p1), t));
    }
    if constexpr (kOutput)
      left_min = horizontalMin(left_path.minimum);
    top_minima[xi] = static_cast<std::uint16_t>(horizontalMin(top_path.minimum));
  }
}

/// The winner of one pixel from the totals of its D disparities, as OpenCV's 3-way SGBM.
struct Winner {
  int disparity;  ///< index of the smallest total
  int cost;       ///< the smallest total
  bool unique;
};

/// Right-to-left path, the total over the three paths, and the disparity of each pixel.
template <int KC>
MSF_AVX2_INLINE void backwardPassFor(const Strip& strip, std::int16_t* out, const int K) {
  const SgmStrip& s = strip.s;
  const Layout& layout = strip.layout;
  const int D = 16 * K, r = s.block_radius, last = layout.width1 - 1;
  const std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  std::int16_t* right = strip.at<std::int16_t>(layout.right);
  std::int16_t* total = strip.at<std::int16_t>(layout.total);
  const std::int16_t* sums = strip.at<std::int16_t>(layout.sums);
  std::int16_t* disp2 = strip.at<std::int16_t>(layout.disp2);
  std::int16_t* disp2_cost = strip.at<std::int16_t>(layout.disp2_cost);
  const __m256i p1 = _mm256_set1_epi16(static_cast<short>(s.p1));
  const int min_d = s.min_disparity, scale = 16, ratio = s.uniqueness_ratio;
  // Ambiguous when another disparity, not next to the best, costs at most
  // min_cost * 100 / (100 - ratio) (OpenCV's vectorised check); the quotient by a
  // reciprocal, corrected to the exact integer one.
  const double reciprocal = ratio < 100 ? 100.0 / (100 - ratio) : 0.0;
  const auto threshold = [&](int min_cost) {
    if (ratio >= 100)
      return 0x7FFF;
    int t = static_cast<int>(min_cost * reciprocal);
    while ((t + 1) * (100 - ratio) <= 100 * min_cost)
      ++t;
    while (t * (100 - ratio) > 100 * min_cost)
      --t;
    return t > 0x7FFF ? 0x7FFF : t;
  };
  startBox(strip, last, -1);
  std::memset(right, 0, sizeof(std::int16_t) * static_cast<std::size_t>(D));
  int right_min = 0;
  for (int xi = last; xi >= 0; --xi) {
    const std::int16_t* entering = column_sums + static_cast<std::size_t>(xi - r > 0 ? xi - r : 0) * D;
    const std::int16_t* leaving = column_sums + static_cast<std::size_t>(xi + r + 1 < last ? xi + r + 1 : last) * D;
    const __m256i first = _mm256_set1_epi16(xi < last ? -1 : 0);
    const std::int16_t* sums_x = sums + static_cast<std::size_t>(xi) * D;
    PathSweep right_path(right, K, right_min, s.p2);
    // Per lane: the smallest total so far and the vector k where it was (the first on ties).
    __m256i best_cost = _mm256_set1_epi16(0x7FFF), best_k = _mm256_setzero_si256();
#pragma GCC unroll 8
    for (int k = 0; k < K; ++k) {
      const __m256i change = _mm256_sub_epi16(load16(entering + 16 * k), load16(leaving + 16 * k));
      const __m256i cost = _mm256_add_epi16(load16(box + 16 * k), _mm256_and_si256(change, first));
      store16(box + 16 * k, cost);
      const __m256i sum = _mm256_adds_epi16(right_path.step(k, cost, p1), load16(sums_x + 16 * k));
      store16(total + 16 * k, sum);
      const __m256i better = _mm256_cmpgt_epi16(best_cost, sum);
      best_cost = _mm256_min_epi16(best_cost, sum);
      best_k = _mm256_blendv_epi8(best_k, _mm256_set1_epi16(static_cast<short>(k)), better);
    }
    right_min = horizontalMin(right_path.minimum);
    const int min_cost = horizontalMin(best_cost);
    const unsigned min_lanes =
        static_cast<unsigned>(_mm256_movemask_epi8(_mm256_cmpeq_epi16(best_cost, _mm256_set1_epi16(static_cast<short>(min_cost)))));
    const int lane = __builtin_ctz(min_lanes) / 2;
    alignas(32) std::int16_t lane_k[16];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lane_k), best_k);
    const int best = 16 * lane_k[lane] + lane;
    if (ratio > 0) {
      // Totals within the threshold (two mask bits each), less the best and its neighbours.
      const int limit = threshold(min_cost);
      const __m256i limit_vector = _mm256_set1_epi16(static_cast<short>(limit));
      int within = 0;
      for (int k = 0; k < K; ++k)
        within += __builtin_popcount(
            ~static_cast<unsigned>(_mm256_movemask_epi8(_mm256_cmpgt_epi16(load16(total + 16 * k), limit_vector))));
      within /= 2;
      for (int d = best - 1; d <= best + 1; ++d)
        within -= d >= 0 && d < D && total[d] <= limit;
      if (within > 0)
        continue;
    }
    const int x = xi + layout.min_x;
    const int x_right = x - best - min_d;
    if (x_right >= 0 && x_right < s.width && disp2_cost[x_right] > min_cost) {
      disp2_cost[x_right] = static_cast<std::int16_t>(min_cost);
      disp2[x_right] = static_cast<std::int16_t>(best + min_d);
    }
    int d = best * scale;
    if (best > 0 && best < D - 1) { // parabola through the best and its neighbours
      const int below = total[best - 1], above = total[best + 1];
      const int curvature = below + above - 2 * total[best];
      const int denominator = curvature > 1 ? curvature : 1;
      // Exactly C's truncating division: |numerator| < 2^21, so the double quotient
      // never rounds across an integer.
      d += static_cast<int>(static_cast<double>((below - above) * scale + denominator) / (denominator * 2));
    }
    out[x] = static_cast<std::int16_t>(d + min_d * scale);
  }
}

template <bool kOutput, int KC>
MSF_AVX2 void forwardPassK(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub) {
  forwardPassFor<kOutput>(strip, add, sub, KC > 0 ? KC : strip.layout.num_disparities / 16);
}

template <int KC>
MSF_AVX2 void backwardPassK(const Strip& strip, std::int16_t* out) {
  backwardPassFor<KC>(strip, out, KC > 0 ? KC : strip.layout.num_disparities / 16);
}

/// The passes of one row, unrolled for up to 128 disparities.
/// `add`, `sub`: the block rows entering and leaving (none at the strip's first row);
/// `out`: the disparity row, none on warm-up rows.
template <int KC>
MSF_AVX2 void matchRow(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, std::int16_t* out) {
  if (!out) {
    forwardPassK<false, KC>(strip, add, sub);
    return;
  }
  forwardPassK<true, KC>(strip, add, sub);
  backwardPassK<KC>(strip, out);
}

using RowMatcher = void (*)(const Strip&, const std::uint8_t*, const std::uint8_t*, std::int16_t*);

RowMatcher rowMatcherFor(int num_disparities) {
  switch (num_disparities / 16) {
  case 1: return matchRow<1>;
  case 2: return matchRow<2>;
  case 3: return matchRow<3>;
  case 4: return matchRow<4>;
  case 5: return matchRow<5>;
  case 6: return matchRow<6>;
  case 7: return matchRow<7>;
  case 8: return matchRow<8>;
  default: return matchRow<0>;
  }
}

} // namespace

MSF_AVX2 void sgmStripAvx2(const SgmStrip& s) {
  const Strip strip(s);
  const Layout& layout = strip.layout;
  const int invalid = (s.min_disparity - 1) * 16;
  int* tags = strip.at<int>(layout.prep_rows);
  for (int i = 0; i < layout.ring; ++i)
    tags[i] = -1;
  if (layout.width1 <= 0) {
    for (int y = s.row_output_begin; y < s.row_end; ++y)
      for (int x = 0; x < s.width; ++x)
        s.disparity[static_cast<std::size_t>(y) * s.disparity_step + x] = static_cast<std::int16_t>(invalid);
    return;
  }
  const int D = s.num_disparities, r = s.block_radius;
  const std::size_t volume_row = static_cast<std::size_t>(layout.width1) * D;
  std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::memset(column_sums, 0, sizeof(std::int16_t) * volume_row);
  for (int k = s.row_begin - r; k <= s.row_begin + r; ++k)
    addRowToColumnSums(strip, strip.preparedRow(k));
  // The top-to-bottom path starts at the strip's first row with L = C.
  std::memset(strip.at<std::int16_t>(layout.top), 0, sizeof(std::int16_t) * volume_row);
  std::memset(strip.at<std::uint16_t>(layout.top_minima), 0, sizeof(std::uint16_t) * static_cast<std::size_t>(layout.width1));
  std::int16_t* disp2 = strip.at<std::int16_t>(layout.disp2);
  std::int16_t* disp2_cost = strip.at<std::int16_t>(layout.disp2_cost);

  const RowMatcher match_row = rowMatcherFor(D);
  for (int y = s.row_begin; y < s.row_end; ++y) {
    const std::uint8_t* add = y > s.row_begin ? strip.preparedRow(y + r) : nullptr;
    const std::uint8_t* sub = y > s.row_begin ? strip.preparedRow(y - r - 1) : nullptr;
    if (y < s.row_output_begin) {
      match_row(strip, add, sub, nullptr);
      continue;
    }
    std::int16_t* out = s.disparity + static_cast<std::size_t>(y) * s.disparity_step;
    for (int x = 0; x < s.width; ++x) {
      out[x] = static_cast<std::int16_t>(invalid);
      disp2[x] = static_cast<std::int16_t>(s.min_disparity - 1);
      disp2_cost[x] = 0x7FFF;
    }
    match_row(strip, add, sub, out);
    // OpenCV's pseudo left-right check: the right view's winners, gathered above from the
    // left view's, must agree with the disparity rounded down or up.
    const int max_diff = s.disp12_max_diff;
    for (int x = layout.min_x; x < layout.min_x + layout.width1; ++x) {
      const int d1 = out[x];
      if (d1 == invalid)
        continue;
      const int d_floor = d1 >> 4, d_ceil = (d1 + 15) >> 4;
      const int x_floor = x - d_floor, x_ceil = x - d_ceil;
      const auto inconsistent = [&](int xr, int d) {
        return xr >= 0 && xr < s.width && disp2[xr] >= s.min_disparity && (disp2[xr] - d > max_diff || d - disp2[xr] > max_diff);
      };
      if (inconsistent(x_floor, d_floor) && inconsistent(x_ceil, d_ceil))
        out[x] = static_cast<std::int16_t>(invalid);
    }
  }
}

#else // not x86: no kernel; SemiGlobalMatcher is never selected

bool sgmAvx2Available() { return false; }
void sgmStripAvx2(const SgmStrip&) {}

#endif

} // namespace msf::detail
