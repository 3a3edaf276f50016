// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The kernel of SemiGlobalMatcher, written once over a vector type V (semi_global_kernel_simd.cpp
// includes it twice: V = 16 x int16 AVX2 lanes and V = 32 x int16 AVX-512BW lanes, each under
// its own target pragma and namespace; semi_global_kernel_portable.cpp once more over 16 lanes
// in plain arrays). No include guard, on purpose; no includes, so that nothing but these
// functions is compiled for the wider instruction set.
//
// Per row, with r the block radius and D the number of disparities (padded to whole vectors
// with lanes that cost the maximum):
//  1. pixel cost: Birchfield-Tomasi dissimilarity of the Sobel-x prefiltered rows (clipped at
//     the prefilter cap) plus a quarter of that of the raw rows, as 8-bit;
//  2. block cost: a running sum over 2r+1 rows per column and disparity (the pixel costs of
//     the row entering and of the row leaving are recomputed rather than stored, so the
//     buffers of a strip stay within a core's L2 cache), then a sliding sum over 2r+1 columns;
//  3. guidance (optional): at pixels with a disparity hint, a penalty growing with the
//     distance from the hint is added to the block costs, so that the paths carry the hint on;
//  4. paths: left-to-right and top-to-bottom in one pass (with diagonal_paths, top-left and
//     top-right too), right-to-left in a second pass that also picks the disparity
//     (uniqueness, parabolic sub-pixel, pseudo left-right check). The paths from above may
//     charge a rise of the disparity by one pixel less than a fall (p1_rise, the ground prior).

// MSF_SIMD_UNROLL(n): the including file's unrolling of a loop over the disparities.
using Reg = typename V::Reg;
constexpr int kLanes = V::kLanes; // 16-bit lanes per vector
constexpr int kBytes = 2 * kLanes;

/// Sobel-x response clipped to [-cap, cap] and shifted to [0, 2 cap], and the raw row, of
/// one image row; the first and last columns hold `cap` in both (as OpenCV's prefilter).
MSF_SIMD void prefilterRow(const std::uint8_t* up, const std::uint8_t* row, const std::uint8_t* down, int width, int cap,
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
MSF_SIMD void halfPixelRange(const std::uint8_t* a, int width, std::uint8_t* low, std::uint8_t* high) {
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

MSF_SIMD void reverseRow(std::uint8_t* a, int width) {
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
  Reg padding; ///< the last vector's lanes beyond D at the maximum cost, the others at the minimum

  MSF_SIMD_INLINE explicit Strip(const SgmStrip& strip)
      : s(strip),
        layout(strip.width, strip.min_disparity, strip.num_disparities,
               (strip.num_disparities + kLanes - 1) / kLanes * kLanes, strip.block_radius, strip.diagonal_paths),
        base(reinterpret_cast<std::uint8_t*>((reinterpret_cast<std::uintptr_t>(strip.workspace) + kAlign - 1) &
                                             ~static_cast<std::uintptr_t>(kAlign - 1))) {
    alignas(64) std::int16_t lanes[kLanes];
    const int valid = strip.num_disparities - (layout.num_disparities - kLanes);
    for (int i = 0; i < kLanes; ++i)
      lanes[i] = static_cast<std::int16_t>(i < valid ? -0x8000 : 0x7FFF);
    padding = V::load(lanes);
  }

  template <typename T>
  T* at(std::size_t offset) const {
    return reinterpret_cast<T*>(base + offset);
  }

  /// The prepared arrays of image row `y` (clamped), computing them if not in the ring.
  MSF_SIMD const std::uint8_t* preparedRow(int y) const {
    y = y < 0 ? 0 : (y >= s.height ? s.height - 1 : y);
    const int slot_index = y % layout.ring;
    int* tags = at<int>(layout.prep_rows);
    std::uint8_t* slot =
        at<std::uint8_t>(layout.prep) + static_cast<std::size_t>(slot_index) * Layout::kPrepArrays * kSgmPrepStride;
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
/// [u0, u1]) against kBytes right values at v (ranges at v0, v1).
MSF_SIMD_INLINE Reg dissimilarity(Reg u, Reg u0, Reg u1, const std::uint8_t* v, const std::uint8_t* v0,
                                  const std::uint8_t* v1) {
  const Reg vv = V::load(v), vv0 = V::load(v0), vv1 = V::load(v1);
  const Reg c0 = V::maxu8(V::subsu8(u, vv1), V::subsu8(vv0, u));
  const Reg c1 = V::maxu8(V::subsu8(vv, u1), V::subsu8(u0, vv));
  return V::minu8(c0, c1);
}

/// Pixel costs of left column x against kBytes consecutive disparities of one prepared row.
struct PixelCost {
  Reg su, su0, su1, ru, ru0, ru1;
  const std::uint8_t* right; // prefiltered right row (reversed) at the first disparity
  /// A constant, so that the six arrays are addressed from one register.
  static constexpr int stride = kSgmPrepStride;

  MSF_SIMD_INLINE PixelCost(const std::uint8_t* prepared, int x, int reversed_first) {
    su = V::set8(prepared[x]);
    su0 = V::set8(prepared[stride + x]);
    su1 = V::set8(prepared[2 * stride + x]);
    ru = V::set8(prepared[3 * stride + x]);
    ru0 = V::set8(prepared[4 * stride + x]);
    ru1 = V::set8(prepared[5 * stride + x]);
    right = prepared + 6 * stride + reversed_first;
  }

  /// Costs of disparities first + d .. first + d + kBytes - 1: prefiltered + raw / 4 (<= 189).
  MSF_SIMD_INLINE Reg operator()(int d) const {
    const std::uint8_t* r = right + d;
    const Reg sobel = dissimilarity(su, su0, su1, r, r + stride, r + 2 * stride);
    const Reg raw = dissimilarity(ru, ru0, ru1, r + 3 * stride, r + 4 * stride, r + 5 * stride);
    return V::addsu8(sobel, V::quarterBytes(raw));
  }
};

/// column_sums of column xi += costs of row `add` - costs of row `sub` (kSubtract) for every
/// disparity, widened to 16 bits in disparity order.
template <bool kSubtract>
MSF_SIMD_INLINE void updateColumn(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, int xi) {
  const Layout& layout = strip.layout;
  const int D = layout.num_disparities;
  const int x = xi + layout.min_x;
  const int reversed_first = strip.s.width - 1 - x + strip.s.min_disparity;
  const PixelCost cost_add(add, x, reversed_first);
  std::int16_t* column = strip.at<std::int16_t>(layout.column_sums) + static_cast<std::size_t>(xi) * D;
  if constexpr (kSubtract) {
    const PixelCost cost_sub(sub, x, reversed_first);
MSF_SIMD_UNROLL(4)
    for (int d = 0; d < D; d += kBytes) {
      Reg low, high;
      V::widenDifference(cost_add(d), cost_sub(d), low, high);
      V::store(column + d, V::add16(V::load(column + d), low));
      if (d + kLanes < D)
        V::store(column + d + kLanes, V::add16(V::load(column + d + kLanes), high));
    }
  } else {
    for (int d = 0; d < D; d += kBytes) {
      Reg low, high;
      V::widen(cost_add(d), low, high);
      V::store(column + d, V::add16(V::load(column + d), low));
      if (d + kLanes < D)
        V::store(column + d + kLanes, V::add16(V::load(column + d + kLanes), high));
    }
  }
}

/// column_sums += costs of row `add` for every column: the strip's first block of rows.
MSF_SIMD void addRowToColumnSums(const Strip& strip, const std::uint8_t* add) {
  for (int xi = 0; xi < strip.layout.width1; ++xi)
    updateColumn<false>(strip, add, nullptr, xi);
}

/// Hirschmueller's recursion for kLanes disparities: cost + min(L(d), L(d-1) + P1,
/// L(d+1) + P1, min L + P2) - min L, with `below` = L(d-1) and `above` = L(d+1) of the
/// previous pixel.
MSF_SIMD_INLINE Reg pathStep(Reg cost, Reg below, Reg above, Reg same, Reg p1, Reg previous_min_p2, Reg previous_min) {
  const Reg m = V::min16(V::adds16(V::min16(below, above), p1), V::min16(same, previous_min_p2));
  return V::adds16(cost, V::sub16(m, previous_min));
}

/// The same with its own penalty for a rise: L(d-1) + p1_rise, where the disparity is one
/// pixel higher than at the previous pixel.
MSF_SIMD_INLINE Reg pathStepRising(Reg cost, Reg below, Reg above, Reg same, Reg p1_rise, Reg p1, Reg previous_min_p2,
                                   Reg previous_min) {
  const Reg m = V::min16(V::min16(V::adds16(below, p1_rise), V::adds16(above, p1)), V::min16(same, previous_min_p2));
  return V::adds16(cost, V::sub16(m, previous_min));
}

/// The guidance penalty of one row: min(gain |d - hint|, max_penalty) for each disparity
/// lane of a pixel with a hint, d and the hint in 1/16 px. gain x min(|d - hint|, cap) stays
/// below 2^16 (cap = the difference at which the penalty reaches its maximum), so the
/// product is exact as unsigned 16-bit.
struct Guide {
  const std::int16_t* hints; ///< the row's hints by image column, nullptr: none in the row
  Reg first, step, cap, gain, max_penalty;

  MSF_SIMD_INLINE Guide(const SgmStrip& s, const std::int16_t* row_hints) : hints(row_hints) {
    first = V::add16(V::set16(16 * s.min_disparity), V::mullo16(V::laneIndex(), V::set16(16)));
    step = V::set16(16 * kLanes);
    const int g = s.guidance_gain > 0 ? s.guidance_gain : 1;
    const int reach = (16 * s.guidance_max_penalty + g - 1) / g;
    cap = V::set16(reach < 0x7FFF ? reach : 0x7FFF);
    gain = V::set16(s.guidance_gain);
    max_penalty = V::set16(s.guidance_max_penalty);
  }

  /// Penalties of vector k at a pixel whose hint is `hint` (disparity x 16).
  MSF_SIMD_INLINE Reg penalty(Reg hint, int k) const {
    const Reg d = V::add16(first, V::mullo16(step, V::set16(k)));
    // Saturated, so that any hint is safe: |-32768| stays 0x8000, above the cap unsigned.
    const Reg distance = V::minu16(V::abs16(V::subs16(d, hint)), cap);
    return V::min16(V::sixteenthU16(V::mullo16(distance, gain)), max_penalty);
  }

  /// A pixel's hint (0: none) and the hint in every lane.
  struct Pixel {
    int hint;
    Reg lanes;
  };
  /// The pixel of image column x.
  MSF_SIMD_INLINE Pixel at(int x) const {
    const int hint = hints ? hints[x] : 0;
    return {hint, V::set16(hint)};
  }
  /// The block costs of vector k at `pixel`, with their penalties where it has a hint.
  MSF_SIMD_INLINE Reg guided(Reg cost, const Pixel& pixel, int k) const {
    if (pixel.hint > 0)
      cost = V::adds16(cost, penalty(pixel.lanes, k));
    return cost;
  }
};

/// One path's state while its D disparities are swept a vector at a time, updating `costs`
/// in place.
struct PathSweep {
  std::int16_t* costs;
  int count; // vectors
  Reg previous, current, minimum, previous_min, previous_min_p2;

  MSF_SIMD_INLINE PathSweep(std::int16_t* costs_, int count_, int previous_minimum, int p2)
      : costs(costs_), count(count_) {
    previous = V::set16(0x7FFF);
    current = V::load(costs);
    minimum = previous;
    previous_min = V::set16(previous_minimum);
    const int with_p2 = previous_minimum + p2;
    previous_min_p2 = V::set16(with_p2 > 0x7FFF ? 0x7FFF : with_p2);
  }

  /// New costs of vector k from `cost`, stored in place; returns them. kRising: a rise of
  /// the disparity by one pixel costs `p1_rise` rather than `p1`.
  template <bool kRising>
  MSF_SIMD_INLINE Reg step(int k, Reg cost, Reg p1, Reg p1_rise) {
    const Reg next = k + 1 < count ? V::load(costs + kLanes * (k + 1)) : V::set16(0x7FFF);
    const Reg below = V::below(previous, current), above = V::above(current, next);
    Reg result;
    if constexpr (kRising)
      result = pathStepRising(cost, below, above, current, p1_rise, p1, previous_min_p2, previous_min);
    else
      result = pathStep(cost, below, above, current, p1, previous_min_p2, previous_min);
    V::store(costs + kLanes * k, result);
    minimum = V::min16(minimum, result);
    previous = current;
    current = next;
    return result;
  }
};

/// box = sum over columns first - r .. first + r (clamped to the matched columns) of the column sums.
MSF_SIMD void startBox(const Strip& strip, int first, int direction) {
  const Layout& layout = strip.layout;
  const int D = layout.num_disparities, r = strip.s.block_radius, last = layout.width1 - 1;
  const std::int16_t* sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  const Reg edge_weight = V::set16(r + 1);
  for (int d = 0; d < D; d += kLanes) {
    Reg acc = V::mullo16(V::load(sums + static_cast<std::size_t>(first) * D + d), edge_weight);
    for (int j = 1; j <= r; ++j) {
      int xi = first + direction * j;
      xi = xi < 0 ? 0 : (xi > last ? last : xi);
      acc = V::adds16(acc, V::load(sums + static_cast<std::size_t>(xi) * D + d));
    }
    V::store(box + d, acc);
  }
}

/// Block cost of vector k at the next column: box += entering - leaving (nothing at the
/// first column, where `step` is 0); the disparities past D get the maximum cost.
MSF_SIMD_INLINE Reg nextCost(const Strip& strip, std::int16_t* box, const std::int16_t* entering,
                             const std::int16_t* leaving, Reg step, int k, int K) {
  const Reg change = V::sub16(V::load(entering + kLanes * k), V::load(leaving + kLanes * k));
  const Reg cost = V::add16(V::load(box + kLanes * k), V::and_(change, step));
  V::store(box + kLanes * k, cost);
  return k == K - 1 ? V::max16(cost, strip.padding) : cost;
}

/// The diagonal paths of one pixel, from the top-left and the top-right pixel of the row
/// above, as OpenCV's MODE_SGBM: their sum is added to the pixel's `sums_x` (output rows).
/// A pixel's predecessor on the top-left path is at column xi - 1 of the row above, so the
/// paths are kept by diagonal, at (xi - row) and (xi + row) modulo the row's width: each
/// pixel's costs overwrite its predecessor's, in place, and the pixels of one row use
/// distinct slots. A path entering at the first (top-left) or last column (top-right) starts
/// with L = C, whatever its slot held. `shift`: the row's index in the strip modulo width1.
template <bool kOutput, bool kRising>
MSF_SIMD_INLINE void diagonalPaths(const Strip& strip, int xi, int shift, std::int16_t* sums_x, const int K) {
  const Layout& layout = strip.layout;
  const int D = kLanes * K, width1 = layout.width1;
  const int left_slot = xi - shift < 0 ? xi - shift + width1 : xi - shift;
  const int right_slot = xi + shift >= width1 ? xi + shift - width1 : xi + shift;
  std::int16_t* top_left = strip.at<std::int16_t>(layout.top_left) + static_cast<std::size_t>(left_slot) * D;
  std::int16_t* top_right = strip.at<std::int16_t>(layout.top_right) + static_cast<std::size_t>(right_slot) * D;
  std::uint16_t* left_minima = strip.at<std::uint16_t>(layout.top_left_minima);
  std::uint16_t* right_minima = strip.at<std::uint16_t>(layout.top_right_minima);
  if (xi == 0) {
    std::memset(top_left, 0, sizeof(std::int16_t) * static_cast<std::size_t>(D));
    left_minima[left_slot] = 0;
  }
  if (xi == width1 - 1) {
    std::memset(top_right, 0, sizeof(std::int16_t) * static_cast<std::size_t>(D));
    right_minima[right_slot] = 0;
  }
  const std::int16_t* costs = strip.at<std::int16_t>(layout.costs);
  const Reg p1 = V::set16(strip.s.p1), p1_rise = V::set16(strip.s.p1_rise);
  PathSweep from_left(top_left, K, left_minima[left_slot], strip.s.p2);
  PathSweep from_right(top_right, K, right_minima[right_slot], strip.s.p2);
MSF_SIMD_UNROLL(8)
  for (int k = 0; k < K; ++k) {
    const Reg cost = V::load(costs + kLanes * k);
    const Reg both =
        V::adds16(from_left.step<kRising>(k, cost, p1, p1_rise), from_right.step<kRising>(k, cost, p1, p1_rise));
    if constexpr (kOutput)
      V::store(sums_x + kLanes * k, V::adds16(V::load(sums_x + kLanes * k), both));
  }
  left_minima[left_slot] = static_cast<std::uint16_t>(V::horizontalMin(from_left.minimum));
  right_minima[right_slot] = static_cast<std::uint16_t>(V::horizontalMin(from_right.minimum));
}

/// Left-to-right and top-to-bottom paths of one row (and the diagonal ones with
/// kDiagonal; kRising: the paths from above with p1_rise); their sum goes to `sums` (output
/// rows). `row`: the row's index in the strip.
/// K (vectors of disparities) is a compile-time constant where forwardPassK is
/// instantiated for it, so that the sweep over disparities unrolls.
/// With `add` (and `sub`), each column's sums first move down one row: the block row
/// entering is `add`, the one leaving `sub` (fused here so the sums are read once).
template <bool kOutput, bool kDiagonal, bool kRising>
MSF_SIMD_INLINE void forwardPassFor(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub,
                                    const Guide& guide, int row, const int K) {
  const Layout& layout = strip.layout;
  const int D = kLanes * K, r = strip.s.block_radius, last = layout.width1 - 1;
  const std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  std::int16_t* left = strip.at<std::int16_t>(layout.left);
  std::int16_t* top = strip.at<std::int16_t>(layout.top);
  std::int16_t* sums = strip.at<std::int16_t>(layout.sums);
  std::uint16_t* top_minima = strip.at<std::uint16_t>(layout.top_minima);
  std::int16_t* costs = strip.at<std::int16_t>(layout.costs);
  const int diagonal_shift = row % layout.width1;
  const Reg p1 = V::set16(strip.s.p1), p1_rise = V::set16(strip.s.p1_rise);
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
    const Reg step = V::set16(xi > 0 ? -1 : 0);
    std::int16_t* top_x = top + static_cast<std::size_t>(xi) * D;
    PathSweep top_path(top_x, K, top_minima[xi], p2);
    PathSweep left_path(left, K, left_min, p2);
    std::int16_t* sums_x = sums + static_cast<std::size_t>(xi) * D;
    const Guide::Pixel pixel = guide.at(xi + layout.min_x);
MSF_SIMD_UNROLL(8)
    for (int k = 0; k < K; ++k) {
      const Reg cost = guide.guided(nextCost(strip, box, entering, leaving, step, k, K), pixel, k);
      if constexpr (kDiagonal)
        V::store(costs + kLanes * k, cost);
      const Reg t = top_path.step<kRising>(k, cost, p1, p1_rise);
      if constexpr (kOutput)
        V::store(sums_x + kLanes * k, V::adds16(left_path.step<false>(k, cost, p1, p1), t));
    }
    if constexpr (kOutput)
      left_min = V::horizontalMin(left_path.minimum);
    top_minima[xi] = static_cast<std::uint16_t>(V::horizontalMin(top_path.minimum));
    // In a loop of their own: with the two above, the paths' state outgrows the registers.
    if constexpr (kDiagonal)
      diagonalPaths<kOutput, kRising>(strip, xi, diagonal_shift, sums_x, K);
  }
}

/// OpenCV's uniqueness check: a pixel is ambiguous when another disparity, not next to the
/// best, costs at most min_cost * 100 / (100 - ratio) (OpenCV's vectorised check); the quotient
/// by a reciprocal, corrected to the exact integer one.
class UniquenessCheck {
public:
  UniquenessCheck(int ratio, int searched)
      : ratio_(ratio), searched_(searched), reciprocal_(ratio < 100 ? 100.0 / (100 - ratio) : 0.0) {}

  /// Whether the totals of K vectors at `total` leave the best disparity ambiguous.
  MSF_SIMD_INLINE bool ambiguous(const std::int16_t* total, int best, int min_cost, int K) const {
    if (ratio_ <= 0)
      return false;
    // Totals within the threshold, less the best and its neighbours.
    const int limit = threshold(min_cost);
    const Reg limit_vector = V::set16(limit);
    int within = 0;
    for (int k = 0; k < K; ++k)
      within += __builtin_popcountll(V::atMostMask(V::load(total + kLanes * k), limit_vector));
    within /= V::kMaskBitsPerLane;
    for (int d = best - 1; d <= best + 1; ++d)
      within -= d >= 0 && d < searched_ && total[d] <= limit;
    return within > 0;
  }

private:
  int threshold(int min_cost) const {
    if (ratio_ >= 100)
      return 0x7FFF;
    int t = static_cast<int>(min_cost * reciprocal_);
    while ((t + 1) * (100 - ratio_) <= 100 * min_cost)
      ++t;
    while (t * (100 - ratio_) > 100 * min_cost)
      --t;
    return t > 0x7FFF ? 0x7FFF : t;
  }

  int ratio_, searched_;
  double reciprocal_;
};

/// The best disparity in 1/16 px, refined by the parabola through it and its neighbours.
MSF_SIMD_INLINE int subpixelDisparity(const std::int16_t* total, int best, int searched) {
  constexpr int scale = 16;
  int d = best * scale;
  if (best > 0 && best < searched - 1) {
    const int below = total[best - 1], above = total[best + 1];
    const int curvature = below + above - 2 * total[best];
    const int denominator = curvature > 1 ? curvature : 1;
    // Exactly C's truncating division: |numerator| < 2^21, so the double quotient never rounds
    // across an integer.
    d += static_cast<int>(static_cast<double>((below - above) * scale + denominator) / (denominator * 2));
  }
  return d;
}

/// Right-to-left path, the total over the paths, and the disparity of each pixel.
MSF_SIMD_INLINE void backwardPassFor(const Strip& strip, std::int16_t* out, const Guide& guide, const int K) {
  const SgmStrip& s = strip.s;
  const Layout& layout = strip.layout;
  const int D = kLanes * K, r = s.block_radius, last = layout.width1 - 1;
  const int searched = s.num_disparities; // D without the padding lanes
  const std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::int16_t* box = strip.at<std::int16_t>(layout.box);
  std::int16_t* right = strip.at<std::int16_t>(layout.right);
  std::int16_t* total = strip.at<std::int16_t>(layout.total);
  const std::int16_t* sums = strip.at<std::int16_t>(layout.sums);
  std::int16_t* disp2 = strip.at<std::int16_t>(layout.disp2);
  std::int16_t* disp2_cost = strip.at<std::int16_t>(layout.disp2_cost);
  const Reg p1 = V::set16(s.p1);
  const int min_d = s.min_disparity, scale = 16;
  const UniquenessCheck uniqueness(s.uniqueness_ratio, searched);
  startBox(strip, last, -1);
  std::memset(right, 0, sizeof(std::int16_t) * static_cast<std::size_t>(D));
  int right_min = 0;
  for (int xi = last; xi >= 0; --xi) {
    const std::int16_t* entering = column_sums + static_cast<std::size_t>(xi - r > 0 ? xi - r : 0) * D;
    const std::int16_t* leaving = column_sums + static_cast<std::size_t>(xi + r + 1 < last ? xi + r + 1 : last) * D;
    const Reg step = V::set16(xi < last ? -1 : 0);
    const std::int16_t* sums_x = sums + static_cast<std::size_t>(xi) * D;
    PathSweep right_path(right, K, right_min, s.p2);
    // Per lane: the smallest total so far and the vector k where it was (the first on ties).
    Reg best_cost = V::set16(0x7FFF), best_k = V::set16(0);
    const Guide::Pixel pixel = guide.at(xi + layout.min_x);
MSF_SIMD_UNROLL(8)
    for (int k = 0; k < K; ++k) {
      const Reg cost = guide.guided(nextCost(strip, box, entering, leaving, step, k, K), pixel, k);
      const Reg sum = V::adds16(right_path.step<false>(k, cost, p1, p1), V::load(sums_x + kLanes * k));
      V::store(total + kLanes * k, sum);
      best_k = V::whereLess(sum, best_cost, V::set16(k), best_k);
      best_cost = V::min16(best_cost, sum);
    }
    right_min = V::horizontalMin(right_path.minimum);
    const int min_cost = V::horizontalMin(best_cost);
    // The lowest disparity among the lanes holding the minimum: the same winner whatever
    // the vector width (and OpenCV's scalar rule).
    const Reg disparity = V::add16(V::mullo16(best_k, V::set16(kLanes)), V::laneIndex());
    const int best = V::horizontalMin(V::whereEqual(best_cost, V::set16(min_cost), disparity, V::set16(0x7FFF)));
    if (uniqueness.ambiguous(total, best, min_cost, K))
      continue;
    const int x = xi + layout.min_x;
    const int x_right = x - best - min_d;
    if (x_right >= 0 && x_right < s.width && disp2_cost[x_right] > min_cost) {
      disp2_cost[x_right] = static_cast<std::int16_t>(min_cost);
      disp2[x_right] = static_cast<std::int16_t>(best + min_d);
    }
    const int d = subpixelDisparity(total, best, searched);
    out[x] = static_cast<std::int16_t>(d + min_d * scale);
  }
}

template <bool kOutput, bool kDiagonal, bool kRising, int KC>
MSF_SIMD void forwardPassK(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, const Guide& guide,
                           int row) {
  const int vectors = KC > 0 ? KC : strip.layout.num_disparities / kLanes;
  forwardPassFor<kOutput, kDiagonal, kRising>(strip, add, sub, guide, row, vectors);
}

template <int KC>
MSF_SIMD void backwardPassK(const Strip& strip, std::int16_t* out, const Guide& guide) {
  backwardPassFor(strip, out, guide, KC > 0 ? KC : strip.layout.num_disparities / kLanes);
}

/// `add`, `sub`: the block rows entering and leaving (none at the strip's first row);
/// `out`: the disparity row, none on warm-up rows; `guide`: the row's hints; `row`: the
/// row's index in the strip.
template <bool kDiagonal, bool kRising, int KC>
MSF_SIMD void matchRow(const Strip& strip, const std::uint8_t* add, const std::uint8_t* sub, const Guide& guide,
                       int row, std::int16_t* out) {
  if (!out) {
    forwardPassK<false, kDiagonal, kRising, KC>(strip, add, sub, guide, row);
    return;
  }
  forwardPassK<true, kDiagonal, kRising, KC>(strip, add, sub, guide, row);
  backwardPassK<KC>(strip, out, guide);
}

using RowMatcher = void (*)(const Strip&, const std::uint8_t*, const std::uint8_t*, const Guide&, int, std::int16_t*);

/// The passes of one row, unrolled for up to 128 disparities (where V unrolls them).
template <bool kDiagonal, bool kRising>
MSF_SIMD RowMatcher rowMatcherFor(int vectors) {
  if constexpr (!V::kUnrolled)
    return matchRow<kDiagonal, kRising, 0>;
  switch (vectors) {
  case 1: return matchRow<kDiagonal, kRising, 1>;
  case 2: return matchRow<kDiagonal, kRising, 2>;
  case 3: return matchRow<kDiagonal, kRising, 3>;
  case 4: return matchRow<kDiagonal, kRising, 4>;
  case 5: return matchRow<kDiagonal, kRising, 5>;
  case 6: return matchRow<kDiagonal, kRising, 6>;
  case 7: return matchRow<kDiagonal, kRising, 7>;
  case 8: return matchRow<kDiagonal, kRising, 8>;
  default: return matchRow<kDiagonal, kRising, 0>;
  }
}

/// The row matcher of the strip's paths: OpenCV's (p1_rise = p1) or with the ground prior.
MSF_SIMD RowMatcher rowMatcher(const SgmStrip& s, int vectors) {
  const bool rising = s.p1_rise != s.p1;
  if (s.diagonal_paths)
    return rising ? rowMatcherFor<true, true>(vectors) : rowMatcherFor<true, false>(vectors);
  return rising ? rowMatcherFor<false, true>(vectors) : rowMatcherFor<false, false>(vectors);
}

/// Row y of the guidance, or nullptr when none of its matched columns has a hint (most rows
/// between two LiDAR rings), so that such rows cost nothing.
MSF_SIMD const std::int16_t* rowHints(const SgmStrip& s, int y, const Layout& layout) {
  const std::int16_t* row = s.guidance + static_cast<std::size_t>(y) * s.guidance_step;
  for (int x = layout.min_x; x < layout.min_x + layout.width1; ++x)
    if (row[x] > 0)
      return row;
  return nullptr;
}

MSF_SIMD void runStrip(const SgmStrip& s) {
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
  const int D = layout.num_disparities, r = s.block_radius;
  const std::size_t volume_row = static_cast<std::size_t>(layout.width1) * D;
  std::int16_t* column_sums = strip.at<std::int16_t>(layout.column_sums);
  std::memset(column_sums, 0, sizeof(std::int16_t) * volume_row);
  for (int k = s.row_begin - r; k <= s.row_begin + r; ++k)
    addRowToColumnSums(strip, strip.preparedRow(k));
  // The top-to-bottom path starts at the strip's first row with L = C.
  std::memset(strip.at<std::int16_t>(layout.top), 0, sizeof(std::int16_t) * volume_row);
  std::memset(strip.at<std::uint16_t>(layout.top_minima), 0,
              sizeof(std::uint16_t) * static_cast<std::size_t>(layout.width1));
  if (s.diagonal_paths) { // so do the diagonal ones
    std::memset(strip.at<std::int16_t>(layout.top_left), 0, sizeof(std::int16_t) * volume_row);
    std::memset(strip.at<std::int16_t>(layout.top_right), 0, sizeof(std::int16_t) * volume_row);
    std::memset(strip.at<std::uint16_t>(layout.top_left_minima), 0,
                sizeof(std::uint16_t) * static_cast<std::size_t>(layout.width1));
    std::memset(strip.at<std::uint16_t>(layout.top_right_minima), 0,
                sizeof(std::uint16_t) * static_cast<std::size_t>(layout.width1));
  }
  std::int16_t* disp2 = strip.at<std::int16_t>(layout.disp2);
  std::int16_t* disp2_cost = strip.at<std::int16_t>(layout.disp2_cost);

  const RowMatcher match_row = rowMatcher(s, D / kLanes);
  const bool guided = s.guidance && s.guidance_gain > 0 && s.guidance_max_penalty > 0;
  for (int y = s.row_begin; y < s.row_end; ++y) {
    const std::uint8_t* add = y > s.row_begin ? strip.preparedRow(y + r) : nullptr;
    const std::uint8_t* sub = y > s.row_begin ? strip.preparedRow(y - r - 1) : nullptr;
    const Guide guide(s, guided ? rowHints(s, y, layout) : nullptr);
    if (y < s.row_output_begin) {
      match_row(strip, add, sub, guide, y - s.row_begin, nullptr);
      continue;
    }
    std::int16_t* out = s.disparity + static_cast<std::size_t>(y) * s.disparity_step;
    for (int x = 0; x < s.width; ++x) {
      out[x] = static_cast<std::int16_t>(invalid);
      disp2[x] = static_cast<std::int16_t>(s.min_disparity - 1);
      disp2_cost[x] = 0x7FFF;
    }
    match_row(strip, add, sub, guide, y - s.row_begin, out);
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
        return xr >= 0 && xr < s.width && disp2[xr] >= s.min_disparity &&
               (disp2[xr] - d > max_diff || d - disp2[xr] > max_diff);
      };
      if (inconsistent(x_floor, d_floor) && inconsistent(x_ceil, d_ceil))
        out[x] = static_cast<std::int16_t>(invalid);
    }
  }
}
