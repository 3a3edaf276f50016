// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Where the buffers of one strip of SemiGlobalMatcher lie in its workspace (private to the
// stereo module): shared by the kernels (semi_global_kernel_simd.cpp and
// semi_global_kernel_portable.cpp), which must agree on it to the byte.
#include <cstddef>
#include <cstdint>

namespace msf::detail {

inline constexpr std::size_t kAlign = 64;
constexpr std::size_t alignUp(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

/// Byte offsets of the buffers of one strip inside its workspace.
struct Layout {
  int width1{0};       ///< columns that can be matched: [min_x, min_x + width1)
  int min_x{0};
  int num_disparities{0}; ///< searched, padded to whole vectors: the stride of the buffers
  int ring{0};         ///< prepared rows kept (2r + 2: the row entering and the one leaving)
  std::size_t column_sums{0}, top{0}, sums{0}, top_minima{0}, box{0}, left{0}, right{0}, total{0};
  std::size_t prep{0}, prep_rows{0}, disp2{0}, disp2_cost{0};
  /// The diagonal paths' rows and minima, and the pixel's block costs they read (empty
  /// without diagonal paths).
  std::size_t top_left{0}, top_right{0}, top_left_minima{0}, top_right_minima{0}, costs{0};
  std::size_t bytes{0};

  Layout(int width, int min_disparity, int searched_disparities, int padded_disparities, int block_radius,
         bool diagonal_paths)
      : num_disparities(padded_disparities) {
    const int max_disparity = min_disparity + searched_disparities;
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
    const std::size_t diagonal = diagonal_paths ? 1 : 0;
    top_left = take(diagonal * volume_row);
    top_right = take(diagonal * volume_row);
    top_left_minima = take(diagonal * sizeof(std::uint16_t) * static_cast<std::size_t>(width1));
    top_right_minima = take(diagonal * sizeof(std::uint16_t) * static_cast<std::size_t>(width1));
    costs = take(diagonal * line);
    bytes = at + kAlign; // the caller's pointer is aligned here
  }

  /// Per prepared row: for each image, the prefiltered row and its Birchfield-Tomasi minimum
  /// and maximum, then the raw row and its minimum and maximum; the right image reversed.
  static constexpr int kPrepArrays = 12;
};

} // namespace msf::detail
