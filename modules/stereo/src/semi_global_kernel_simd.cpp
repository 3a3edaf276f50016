// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The vector kernels of SemiGlobalMatcher: OpenCV's StereoSGBM (MODE_SGBM_3WAY, or with the
// two diagonal paths from above, MODE_SGBM's five) cost, aggregation and winner selection, and
// the ground prior of the paths from above (semi_global_kernel_body.h), compiled twice, for
// AVX2 (16 disparities per instruction) and AVX-512BW (32). Only the code between the target
// pragmas uses those instruction sets, so this file builds for any x86-64 and the caller picks
// a kernel at run time (semi_global_kernel_portable.cpp where the CPU has neither).
#include "semi_global_kernel.h"
#include "semi_global_layout.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MSF_SGM_X86 1
#endif

#include <cstring>

namespace msf::detail {

std::size_t sgmWorkspaceBytes(int width, int min_disparity, int num_disparities, int block_radius,
                              bool diagonal_paths) {
  // Disparities padded to whole vectors of the widest kernel (32 lanes).
  return Layout(width, min_disparity, num_disparities, (num_disparities + 31) / 32 * 32, block_radius, diagonal_paths)
      .bytes;
}

#ifdef MSF_SGM_X86

bool sgmAvx2Available() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

bool sgmAvx512Available() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx2");
}

// noinline: one symbol per stage in a profile; each is called once per row or more rarely.
#define MSF_SIMD __attribute__((noinline))
#define MSF_SIMD_INLINE __attribute__((always_inline)) inline
#define MSF_SIMD_PRAGMA(x) _Pragma(#x)
#define MSF_SIMD_UNROLL(n) MSF_SIMD_PRAGMA(GCC unroll n)

#pragma GCC push_options
#pragma GCC target("avx2")
namespace avx2 {
namespace {

/// 16 x int16 (32 x uint8) in a 256-bit register.
struct V {
  using Reg = __m256i;
  static constexpr int kLanes = 16;
  static constexpr int kMaskBitsPerLane = 2; // movemask_epi8 gives one bit per byte
  static constexpr bool kUnrolled = true;   // a row matcher per number of vectors
  MSF_SIMD_INLINE static Reg load(const void* p) { return _mm256_loadu_si256(static_cast<const __m256i*>(p)); }
  MSF_SIMD_INLINE static void store(void* p, Reg v) { _mm256_storeu_si256(static_cast<__m256i*>(p), v); }
  MSF_SIMD_INLINE static Reg set16(int v) { return _mm256_set1_epi16(static_cast<short>(v)); }
  MSF_SIMD_INLINE static Reg set8(int v) { return _mm256_set1_epi8(static_cast<char>(v)); }
  MSF_SIMD_INLINE static Reg add16(Reg a, Reg b) { return _mm256_add_epi16(a, b); }
  MSF_SIMD_INLINE static Reg adds16(Reg a, Reg b) { return _mm256_adds_epi16(a, b); }
  MSF_SIMD_INLINE static Reg sub16(Reg a, Reg b) { return _mm256_sub_epi16(a, b); }
  MSF_SIMD_INLINE static Reg min16(Reg a, Reg b) { return _mm256_min_epi16(a, b); }
  MSF_SIMD_INLINE static Reg max16(Reg a, Reg b) { return _mm256_max_epi16(a, b); }
  MSF_SIMD_INLINE static Reg abs16(Reg a) { return _mm256_abs_epi16(a); }
  MSF_SIMD_INLINE static Reg subs16(Reg a, Reg b) { return _mm256_subs_epi16(a, b); }
  MSF_SIMD_INLINE static Reg minu16(Reg a, Reg b) { return _mm256_min_epu16(a, b); }
  /// Unsigned 16-bit lanes divided by 16.
  MSF_SIMD_INLINE static Reg sixteenthU16(Reg a) { return _mm256_srli_epi16(a, 4); }
  MSF_SIMD_INLINE static Reg mullo16(Reg a, Reg b) { return _mm256_mullo_epi16(a, b); }
  MSF_SIMD_INLINE static Reg and_(Reg a, Reg b) { return _mm256_and_si256(a, b); }
  MSF_SIMD_INLINE static Reg subsu8(Reg a, Reg b) { return _mm256_subs_epu8(a, b); }
  MSF_SIMD_INLINE static Reg maxu8(Reg a, Reg b) { return _mm256_max_epu8(a, b); }
  MSF_SIMD_INLINE static Reg minu8(Reg a, Reg b) { return _mm256_min_epu8(a, b); }
  MSF_SIMD_INLINE static Reg addsu8(Reg a, Reg b) { return _mm256_adds_epu8(a, b); }
  MSF_SIMD_INLINE static Reg quarterBytes(Reg a) { return _mm256_and_si256(_mm256_srli_epi16(a, 2), set8(0x3F)); }
  /// L(d - 1) of `current`'s lanes, given the vector before it.
  MSF_SIMD_INLINE static Reg below(Reg previous, Reg current) {
    return _mm256_alignr_epi8(current, _mm256_permute2x128_si256(previous, current, 0x21), 14);
  }
  /// L(d + 1) of `current`'s lanes, given the vector after it.
  MSF_SIMD_INLINE static Reg above(Reg current, Reg next) {
    return _mm256_alignr_epi8(_mm256_permute2x128_si256(current, next, 0x21), current, 2);
  }
  /// a - b of 32 bytes as int16, disparities 0..15 in `low` and 16..31 in `high`: the
  /// qwords reordered so that the in-lane unpacks keep disparity order, and maddubs with
  /// (+1, -1) byte pairs subtracting.
  MSF_SIMD_INLINE static void widenDifference(Reg a, Reg b, Reg& low, Reg& high) {
    const Reg plus_minus = set16(static_cast<short>(0xFF01));
    a = _mm256_permute4x64_epi64(a, 0xD8);
    b = _mm256_permute4x64_epi64(b, 0xD8);
    low = _mm256_maddubs_epi16(_mm256_unpacklo_epi8(a, b), plus_minus);
    high = _mm256_maddubs_epi16(_mm256_unpackhi_epi8(a, b), plus_minus);
  }
  MSF_SIMD_INLINE static void widen(Reg a, Reg& low, Reg& high) {
    low = _mm256_cvtepu8_epi16(_mm256_castsi256_si128(a));
    high = _mm256_cvtepu8_epi16(_mm256_extracti128_si256(a, 1));
  }
  /// Smallest of the lanes, all non-negative.
  MSF_SIMD_INLINE static int horizontalMin(Reg v) {
    const __m128i m = _mm_min_epu16(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    return _mm_cvtsi128_si32(_mm_minpos_epu16(m)) & 0xFFFF;
  }
  /// `candidate` where a < b, else `current`.
  MSF_SIMD_INLINE static Reg whereLess(Reg a, Reg b, Reg candidate, Reg current) {
    return _mm256_blendv_epi8(current, candidate, _mm256_cmpgt_epi16(b, a));
  }
  /// `candidate` where a == b, else `current`.
  MSF_SIMD_INLINE static Reg whereEqual(Reg a, Reg b, Reg candidate, Reg current) {
    return _mm256_blendv_epi8(current, candidate, _mm256_cmpeq_epi16(a, b));
  }
  MSF_SIMD_INLINE static Reg laneIndex() { return _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15); }
  MSF_SIMD_INLINE static unsigned long long atMostMask(Reg a, Reg limit) {
    return ~static_cast<unsigned>(_mm256_movemask_epi8(_mm256_cmpgt_epi16(a, limit)));
  }
};

#include "semi_global_kernel_body.h"

} // namespace
} // namespace avx2
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512bw")
// GCC 12's AVX-512 intrinsics pass an undefined vector as the unused masked-off operand,
// which -Wmaybe-uninitialized reports at every use.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
namespace avx512 {
namespace {

/// 32 x int16 (64 x uint8) in a 512-bit register.
struct V {
  using Reg = __m512i;
  static constexpr int kLanes = 32;
  static constexpr int kMaskBitsPerLane = 1;
  static constexpr bool kUnrolled = true;
  MSF_SIMD_INLINE static Reg load(const void* p) { return _mm512_loadu_si512(p); }
  MSF_SIMD_INLINE static void store(void* p, Reg v) { _mm512_storeu_si512(p, v); }
  MSF_SIMD_INLINE static Reg set16(int v) { return _mm512_set1_epi16(static_cast<short>(v)); }
  MSF_SIMD_INLINE static Reg set8(int v) { return _mm512_set1_epi8(static_cast<char>(v)); }
  MSF_SIMD_INLINE static Reg add16(Reg a, Reg b) { return _mm512_add_epi16(a, b); }
  MSF_SIMD_INLINE static Reg adds16(Reg a, Reg b) { return _mm512_adds_epi16(a, b); }
  MSF_SIMD_INLINE static Reg sub16(Reg a, Reg b) { return _mm512_sub_epi16(a, b); }
  MSF_SIMD_INLINE static Reg min16(Reg a, Reg b) { return _mm512_min_epi16(a, b); }
  MSF_SIMD_INLINE static Reg max16(Reg a, Reg b) { return _mm512_max_epi16(a, b); }
  MSF_SIMD_INLINE static Reg abs16(Reg a) { return _mm512_abs_epi16(a); }
  MSF_SIMD_INLINE static Reg subs16(Reg a, Reg b) { return _mm512_subs_epi16(a, b); }
  MSF_SIMD_INLINE static Reg minu16(Reg a, Reg b) { return _mm512_min_epu16(a, b); }
  MSF_SIMD_INLINE static Reg sixteenthU16(Reg a) { return _mm512_srli_epi16(a, 4); }
  MSF_SIMD_INLINE static Reg mullo16(Reg a, Reg b) { return _mm512_mullo_epi16(a, b); }
  MSF_SIMD_INLINE static Reg and_(Reg a, Reg b) { return _mm512_and_si512(a, b); }
  MSF_SIMD_INLINE static Reg subsu8(Reg a, Reg b) { return _mm512_subs_epu8(a, b); }
  MSF_SIMD_INLINE static Reg maxu8(Reg a, Reg b) { return _mm512_max_epu8(a, b); }
  MSF_SIMD_INLINE static Reg minu8(Reg a, Reg b) { return _mm512_min_epu8(a, b); }
  MSF_SIMD_INLINE static Reg addsu8(Reg a, Reg b) { return _mm512_adds_epu8(a, b); }
  MSF_SIMD_INLINE static Reg quarterBytes(Reg a) { return _mm512_and_si512(_mm512_srli_epi16(a, 2), set8(0x3F)); }
  /// L(d - 1): each 128-bit lane with the one below it (valignq), then a byte shift.
  MSF_SIMD_INLINE static Reg below(Reg previous, Reg current) {
    return _mm512_alignr_epi8(current, _mm512_alignr_epi64(current, previous, 6), 14);
  }
  /// L(d + 1): each 128-bit lane with the one above it, then a byte shift.
  MSF_SIMD_INLINE static Reg above(Reg current, Reg next) {
    return _mm512_alignr_epi8(_mm512_alignr_epi64(next, current, 2), current, 2);
  }
  MSF_SIMD_INLINE static void widenDifference(Reg a, Reg b, Reg& low, Reg& high) {
    const Reg plus_minus = set16(static_cast<short>(0xFF01));
    const Reg order = _mm512_setr_epi64(0, 4, 1, 5, 2, 6, 3, 7);
    a = _mm512_permutexvar_epi64(order, a);
    b = _mm512_permutexvar_epi64(order, b);
    low = _mm512_maddubs_epi16(_mm512_unpacklo_epi8(a, b), plus_minus);
    high = _mm512_maddubs_epi16(_mm512_unpackhi_epi8(a, b), plus_minus);
  }
  MSF_SIMD_INLINE static void widen(Reg a, Reg& low, Reg& high) {
    low = _mm512_cvtepu8_epi16(_mm512_castsi512_si256(a));
    high = _mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(a, 1));
  }
  MSF_SIMD_INLINE static int horizontalMin(Reg v) {
    const __m256i h = _mm256_min_epu16(_mm512_castsi512_si256(v), _mm512_extracti64x4_epi64(v, 1));
    const __m128i m = _mm_min_epu16(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
    return _mm_cvtsi128_si32(_mm_minpos_epu16(m)) & 0xFFFF;
  }
  MSF_SIMD_INLINE static Reg whereLess(Reg a, Reg b, Reg candidate, Reg current) {
    return _mm512_mask_mov_epi16(current, _mm512_cmplt_epi16_mask(a, b), candidate);
  }
  MSF_SIMD_INLINE static Reg whereEqual(Reg a, Reg b, Reg candidate, Reg current) {
    return _mm512_mask_mov_epi16(current, _mm512_cmpeq_epi16_mask(a, b), candidate);
  }
  MSF_SIMD_INLINE static Reg laneIndex() {
    return _mm512_set_epi16(31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19, 18, 17, 16, 15, 14, 13, 12, 11, 10, 9,
                            8, 7, 6, 5, 4, 3, 2, 1, 0);
  }
  MSF_SIMD_INLINE static unsigned long long atMostMask(Reg a, Reg limit) { return _mm512_cmple_epi16_mask(a, limit); }
};

#include "semi_global_kernel_body.h"

} // namespace
} // namespace avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options

void sgmStripAvx2(const SgmStrip& strip) { avx2::runStrip(strip); }
void sgmStripAvx512(const SgmStrip& strip) { avx512::runStrip(strip); }

#else // not x86: no vector kernel; the portable one runs

bool sgmAvx2Available() { return false; }
bool sgmAvx512Available() { return false; }
void sgmStripAvx2(const SgmStrip&) {}
void sgmStripAvx512(const SgmStrip&) {}

#endif

} // namespace msf::detail
