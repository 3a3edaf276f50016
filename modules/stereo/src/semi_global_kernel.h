// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The vectorised core of SemiGlobalMatcher (private to the stereo module): one horizontal
// strip of rows of OpenCV's 3-way semi-global block matching (5-way with the diagonal paths
// from above, as its MODE_SGBM; with p1_rise, the ground prior of the paths from above). Kept
// free of OpenCV and of the standard library's templates so that its kernels can be compiled
// for AVX2 and AVX-512 without lending such copies of inline functions to the rest of the
// program. Every kernel gives the same result to the bit.
#include <cstddef>
#include <cstdint>

namespace msf::detail {

/// Bytes per prepared row array, a compile-time constant so that the kernel addresses its
/// arrays from one register; it bounds the image width.
constexpr int kSgmPrepStride = 4096;
/// Widest image the kernel matches (the rest of a row array pads the 32-byte loads).
constexpr int kSgmMaxWidth = kSgmPrepStride - 64;

/// One strip: the rows [row_output_begin, row_end) are written to `disparity`; the rows
/// [row_begin, row_output_begin) before them only warm up the top-to-bottom path.
struct SgmStrip {
  const std::uint8_t* left{nullptr};  ///< grey, height rows of `width` bytes
  const std::uint8_t* right{nullptr};
  std::size_t left_step{0}, right_step{0}; ///< bytes between rows
  int width{0}, height{0};
  int min_disparity{0};
  int num_disparities{16};            ///< a positive multiple of 16
  int block_radius{2};                ///< (block_size - 1) / 2
  int p1{200}, p2{800};               ///< p2 > p1 > 0
  /// The paths from above (top-to-bottom, and the diagonal ones) charge p1_rise rather than
  /// p1 where the disparity is one pixel higher than at the pixel above: the ground comes
  /// nearer row by row down the image. 0 < p1_rise < p2; p1: OpenCV's paths.
  int p1_rise{200};
  int prefilter_cap{63};              ///< OpenCV's ftzero: max(pre_filter_cap, 15) | 1
  int uniqueness_ratio{10};           ///< percent; 0 = off
  int disp12_max_diff{1};             ///< pseudo left-right check, >= 0
  /// Also the paths from the top-left and the top-right (OpenCV's MODE_SGBM: five in all).
  bool diagonal_paths{false};
  int row_begin{0}, row_output_begin{0}, row_end{0};
  /// Optional guidance (Poggi et al., CVPR 2019, as an additive cost): disparity x 16 of the
  /// left view per pixel, <= 0 = no hint; where there is one, every disparity d's block cost
  /// grows by min(guidance_gain * |d - hint|, guidance_max_penalty) before the paths.
  /// nullptr: no guidance, and exactly the unguided result.
  const std::int16_t* guidance{nullptr};
  std::size_t guidance_step{0};       ///< elements between rows
  /// Cost per pixel of disparity and the largest penalty: 16 x max_penalty + gain < 2^16
  /// (the penalty is computed in unsigned 16-bit lanes); either 0: no guidance.
  int guidance_gain{0};
  int guidance_max_penalty{0};
  std::int16_t* disparity{nullptr};   ///< CV_16S disparity x 16 of the whole image
  std::size_t disparity_step{0};      ///< elements between rows
  std::uint8_t* workspace{nullptr};   ///< sgmWorkspaceBytes() bytes, owned by the caller
};

/// Bytes of workspace one strip needs for images `width` wide.
std::size_t sgmWorkspaceBytes(int width, int min_disparity, int num_disparities, int block_radius,
                              bool diagonal_paths);

/// Runs one strip with AVX2 instructions; call only where the CPU has them.
void sgmStripAvx2(const SgmStrip& strip);
/// The same with AVX-512BW (32 disparities per instruction); the same result.
void sgmStripAvx512(const SgmStrip& strip);
/// The same in portable C++ (16 disparities per step, as AVX2's lanes); the same result.
void sgmStripPortable(const SgmStrip& strip);

/// True when this build has the AVX2 kernel and the CPU runs AVX2.
bool sgmAvx2Available();
/// True when this build has the AVX-512 kernel and the CPU runs AVX-512F and BW.
bool sgmAvx512Available();

} // namespace msf::detail
