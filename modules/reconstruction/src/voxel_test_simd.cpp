// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The wide voxel tests (see voxel_test.h): the portable kernel's float operations, lane for
// lane and in the same order, on two rows of a sub-block at once (AVX2, 8 lanes) or four (AVX-512,
// 16), with gathers for the pixels' depths and bands and compressing stores for the candidates.
// Only the code between the target pragmas uses those instruction sets, so this file builds for
// any x86-64 and the caller picks a kernel at run time. Built with -ffp-contract=off: an FMA
// would round X, u or v differently from the portable kernel, and move voxels across pixels.
#include "voxel_test.h"
#include "voxel_update.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MSF_VOXEL_TEST_X86 1
#endif

#include <array>
#include <cstddef>
#include <cstring>

namespace msf::detail {

#ifdef MSF_VOXEL_TEST_X86

namespace {

static_assert(sizeof(PixelBand) == 5 * sizeof(float), "the gathers index PixelBand's fields as floats");

#define MSF_SIMD_INLINE __attribute__((always_inline)) inline

/// For mask m of 8 lanes, the indices of its set lanes in order, a byte each (AVX2 has no compress).
constexpr std::array<std::uint64_t, 256> makeCompressTable() {
  std::array<std::uint64_t, 256> table{};
  for (int m = 0; m < 256; ++m) {
    int k = 0;
    for (int i = 0; i < 8; ++i)
      if ((m >> i) & 1)
        table[m] |= static_cast<std::uint64_t>(i) << (8 * k++);
  }
  return table;
}
constexpr std::array<std::uint64_t, 256> kCompressTable = makeCompressTable();

} // namespace

#pragma GCC push_options
#pragma GCC target("avx2,popcnt")
namespace avx2 {
namespace {

/// 8 floats: two rows of 4 voxels.
struct V {
  using F = __m256;
  using I = __m256i;
  using M = __m256; ///< all bits of a lane set where true
  static constexpr int kRows = 2;
  static constexpr int kLanes = 8;
  MSF_SIMD_INLINE static F load(const float* p) { return _mm256_loadu_ps(p); }
  MSF_SIMD_INLINE static I loadi(const std::int32_t* p) {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
  }
  /// Lanes 0 .. n - 1.
  MSF_SIMD_INLINE static M firstLanes(int n) {
    return _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
  }
  MSF_SIMD_INLINE static M or_(M a, M b) { return _mm256_or_ps(a, b); }
  MSF_SIMD_INLINE static M andnot(M a, M b) { return _mm256_andnot_ps(b, a); } ///< a and not b (also floats' bits)
  MSF_SIMD_INLINE static F xor_(F a, F b) { return _mm256_xor_ps(a, b); }
  MSF_SIMD_INLINE static F select(M m, F a, F b) { return _mm256_blendv_ps(b, a, m); }
  MSF_SIMD_INLINE static I selecti(M m, I a, I b) {
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(b), _mm256_castsi256_ps(a), m));
  }
  MSF_SIMD_INLINE static M lti(I a, I b) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(b, a)); }
  MSF_SIMD_INLINE static M eqi(I a, I b) { return _mm256_castsi256_ps(_mm256_cmpeq_epi32(a, b)); }
  MSF_SIMD_INLINE static F cvtf(I a) { return _mm256_cvtepi32_ps(a); }
  MSF_SIMD_INLINE static I subi(I a, I b) { return _mm256_sub_epi32(a, b); }
  MSF_SIMD_INLINE static I andi(I a, I b) { return _mm256_and_si256(a, b); }
  MSF_SIMD_INLINE static I ori(I a, I b) { return _mm256_or_si256(a, b); }
  MSF_SIMD_INLINE static I srli(I a, int n) { return _mm256_srli_epi32(a, n); }
  MSF_SIMD_INLINE static I slli(I a, int n) { return _mm256_slli_epi32(a, n); }
  MSF_SIMD_INLINE static I srlv(I a, I n) { return _mm256_srlv_epi32(a, n); }
  MSF_SIMD_INLINE static I sllv(I a, I n) { return _mm256_sllv_epi32(a, n); }
  MSF_SIMD_INLINE static I times3(I a) { return _mm256_add_epi32(a, _mm256_add_epi32(a, a)); }
  /// Gathers where m is set, 0 elsewhere (no access there).
  MSF_SIMD_INLINE static F gatherm(const float* base, I index, M m) {
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, index, m, 4);
  }
  MSF_SIMD_INLINE static I gatheri4(const std::int32_t* base, I index, M m) {
    return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base), index,
                                       _mm256_castps_si256(m), 4);
  }
  /// 4 bytes at base + index.
  MSF_SIMD_INLINE static I gatheri1(const std::uint8_t* base, I index, M m) {
    return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base), index,
                                       _mm256_castps_si256(m), 1);
  }
  /// The first 4 fields of the records (of 5 floats) at `index` where m is set, 0 elsewhere.
  MSF_SIMD_INLINE static void records4(const float* base, I index, M m, F& a, F& b, F& c, F& d) {
    const I at = times5(index);
    a = gatherm(base, at, m);
    b = gatherm(base + 1, at, m);
    c = gatherm(base + 2, at, m);
    d = gatherm(base + 3, at, m);
  }
  /// No scatter in AVX2: a lane at a time.
  MSF_SIMD_INLINE static void scatter(float* base, I index, M m, F v) {
    alignas(32) std::int32_t at[8];
    alignas(32) float value[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(at), index);
    _mm256_store_ps(value, v);
    for (unsigned lanes = bits(m); lanes; lanes &= lanes - 1) {
      const int k = __builtin_ctz(lanes);
      base[at[k]] = value[k];
    }
  }
  MSF_SIMD_INLINE static void scatteri(std::int32_t* base, I index, M m, I v) {
    alignas(32) std::int32_t at[8], value[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(at), index);
    _mm256_store_si256(reinterpret_cast<__m256i*>(value), v);
    for (unsigned lanes = bits(m); lanes; lanes &= lanes - 1) {
      const int k = __builtin_ctz(lanes);
      std::memcpy(base + at[k], &value[k], sizeof(value[k]));
    }
  }
  MSF_SIMD_INLINE static unsigned orLanes(I a) {
    const __m128i x = _mm_or_si128(_mm256_castsi256_si128(a), _mm256_extracti128_si256(a, 1));
    const __m128i y = _mm_or_si128(x, _mm_shuffle_epi32(x, 0x4e));
    return static_cast<unsigned>(_mm_cvtsi128_si32(_mm_or_si128(y, _mm_shuffle_epi32(y, 0xb1))));
  }
  MSF_SIMD_INLINE static F set1(float x) { return _mm256_set1_ps(x); }
  MSF_SIMD_INLINE static I set1i(int x) { return _mm256_set1_epi32(x); }
  MSF_SIMD_INLINE static F xLanes() { return _mm256_setr_ps(0, 1, 2, 3, 0, 1, 2, 3); }
  MSF_SIMD_INLINE static F yLanes() { return _mm256_setr_ps(0, 0, 0, 0, 1, 1, 1, 1); }
  MSF_SIMD_INLINE static I voxelLanes() { return _mm256_setr_epi32(0, 1, 2, 3, 8, 9, 10, 11); }
  MSF_SIMD_INLINE static F add(F a, F b) { return _mm256_add_ps(a, b); }
  MSF_SIMD_INLINE static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
  MSF_SIMD_INLINE static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
  MSF_SIMD_INLINE static F div(F a, F b) { return _mm256_div_ps(a, b); }
  /// a > b ? a : b and a < b ? a : b, as the portable kernel's selections (NaN gives b).
  MSF_SIMD_INLINE static F max(F a, F b) { return _mm256_max_ps(a, b); }
  MSF_SIMD_INLINE static F min(F a, F b) { return _mm256_min_ps(a, b); }
  MSF_SIMD_INLINE static M ge(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
  MSF_SIMD_INLINE static M gt(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
  MSF_SIMD_INLINE static M le(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
  MSF_SIMD_INLINE static M lt(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
  MSF_SIMD_INLINE static M and_(M a, M b) { return _mm256_and_ps(a, b); }
  MSF_SIMD_INLINE static unsigned bits(M m) { return static_cast<unsigned>(_mm256_movemask_ps(m)); }
  MSF_SIMD_INLINE static I cvtt(F a) { return _mm256_cvttps_epi32(a); }
  MSF_SIMD_INLINE static I addi(I a, I b) { return _mm256_add_epi32(a, b); }
  MSF_SIMD_INLINE static I mullo(I a, I b) { return _mm256_mullo_epi32(a, b); }
  MSF_SIMD_INLINE static I times5(I a) { return _mm256_add_epi32(a, _mm256_slli_epi32(a, 2)); }
  MSF_SIMD_INLINE static F gather(const float* base, I index) { return _mm256_i32gather_ps(base, index, 4); }
  /// Stores the set lanes of a vector, in order, at dst (and anything after them, up to 8 lanes).
  struct Compress {
    I order;
    MSF_SIMD_INLINE explicit Compress(unsigned lanes)
        : order(_mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kCompressTable[lanes])))) {}
    MSF_SIMD_INLINE void store(float* dst, F v) const { _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(v, order)); }
    MSF_SIMD_INLINE void store(std::int32_t* dst, I v) const {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst), _mm256_permutevar8x32_epi32(v, order));
    }
    /// As 16-bit values (v's lanes in 0 .. 65535).
    MSF_SIMD_INLINE void store16(std::uint16_t* dst, I v) const {
      const __m256i p = _mm256_permutevar8x32_epi32(v, order);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(dst),
                       _mm_packus_epi32(_mm256_castsi256_si128(p), _mm256_extracti128_si256(p, 1)));
    }
  };
};

#include "voxel_test_body.h"
#include "voxel_update_body.h"

int run(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz, VoxelCandidates& out, int count) {
  return testSubBlock<V>(f, b, sx, sy, sz, out, count);
}

VoxelUpdateResult update(const VoxelUpdateFrame& f, const VoxelCandidates& c, int count, TsdfVoxel* voxels,
                         std::uint16_t* listed_index, float* listed_sdf) {
  return updateBlock<V>(f, c, count, voxels, listed_index, listed_sdf);
}

} // namespace
} // namespace avx2
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2,avx512f,popcnt")
// GCC 12's AVX-512 intrinsics pass an undefined vector as the unused masked-off operand,
// which -Wuninitialized and -Wmaybe-uninitialized report at every use.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
namespace avx512 {
namespace {

/// 16 floats: four rows of 4 voxels, a z slice of the sub-block.
struct V {
  using F = __m512;
  using I = __m512i;
  using M = __mmask16;
  static constexpr int kRows = 4;
  static constexpr int kLanes = 16;
  MSF_SIMD_INLINE static F load(const float* p) { return _mm512_loadu_ps(p); }
  MSF_SIMD_INLINE static I loadi(const std::int32_t* p) { return _mm512_loadu_si512(p); }
  MSF_SIMD_INLINE static M firstLanes(int n) { return n >= 16 ? M(0xffff) : static_cast<M>((1u << n) - 1); }
  MSF_SIMD_INLINE static M or_(M a, M b) { return static_cast<M>(a | b); }
  MSF_SIMD_INLINE static M andnot(M a, M b) { return static_cast<M>(a & ~b); }
  MSF_SIMD_INLINE static F andnot(F a, F b) {
    return _mm512_castsi512_ps(_mm512_andnot_si512(_mm512_castps_si512(b), _mm512_castps_si512(a)));
  }
  MSF_SIMD_INLINE static F xor_(F a, F b) {
    return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_castps_si512(b)));
  }
  MSF_SIMD_INLINE static F select(M m, F a, F b) { return _mm512_mask_blend_ps(m, b, a); }
  MSF_SIMD_INLINE static I selecti(M m, I a, I b) { return _mm512_mask_blend_epi32(m, b, a); }
  MSF_SIMD_INLINE static M lti(I a, I b) { return _mm512_cmplt_epi32_mask(a, b); }
  MSF_SIMD_INLINE static M eqi(I a, I b) { return _mm512_cmpeq_epi32_mask(a, b); }
  MSF_SIMD_INLINE static F cvtf(I a) { return _mm512_cvtepi32_ps(a); }
  MSF_SIMD_INLINE static I subi(I a, I b) { return _mm512_sub_epi32(a, b); }
  MSF_SIMD_INLINE static I andi(I a, I b) { return _mm512_and_si512(a, b); }
  MSF_SIMD_INLINE static I ori(I a, I b) { return _mm512_or_si512(a, b); }
  MSF_SIMD_INLINE static I srli(I a, unsigned n) { return _mm512_srli_epi32(a, n); }
  MSF_SIMD_INLINE static I slli(I a, unsigned n) { return _mm512_slli_epi32(a, n); }
  MSF_SIMD_INLINE static I srlv(I a, I n) { return _mm512_srlv_epi32(a, n); }
  MSF_SIMD_INLINE static I sllv(I a, I n) { return _mm512_sllv_epi32(a, n); }
  MSF_SIMD_INLINE static I times3(I a) { return _mm512_add_epi32(a, _mm512_add_epi32(a, a)); }
  /// Gathers where m is set, 0 elsewhere (no access there).
  MSF_SIMD_INLINE static F gatherm(const float* base, I index, M m) {
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), m, index, base, 4);
  }
  MSF_SIMD_INLINE static I gatheri4(const std::int32_t* base, I index, M m) {
    return _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), m, index, base, 4);
  }
  /// 4 bytes at base + index.
  MSF_SIMD_INLINE static I gatheri1(const std::uint8_t* base, I index, M m) {
    return _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), m, index, base, 1);
  }
  /// The first 4 fields of the records (of 5 floats) at `index` where m is set (record 0's
  /// elsewhere): a 16-byte load per lane and a 4x4 transpose, cheaper than 4 gathers.
  MSF_SIMD_INLINE static void records4(const float* base, I index, M m, F& a, F& b, F& c, F& d) {
    alignas(64) std::int32_t at[16];
    _mm512_store_si512(at, _mm512_maskz_mov_epi32(m, times5(index)));
    F r[4];
    for (int j = 0; j < 4; ++j) // lanes j, j + 4, j + 8, j + 12 in the 4 quarters
      r[j] = _mm512_insertf32x4(
          _mm512_insertf32x4(_mm512_insertf32x4(_mm512_castps128_ps512(_mm_loadu_ps(base + at[j])),
                                                _mm_loadu_ps(base + at[j + 4]), 1),
                             _mm_loadu_ps(base + at[j + 8]), 2),
          _mm_loadu_ps(base + at[j + 12]), 3);
    const F t0 = _mm512_unpacklo_ps(r[0], r[1]), t1 = _mm512_unpackhi_ps(r[0], r[1]);
    const F t2 = _mm512_unpacklo_ps(r[2], r[3]), t3 = _mm512_unpackhi_ps(r[2], r[3]);
    a = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
    b = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
    c = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
    d = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
  }
  MSF_SIMD_INLINE static void scatter(float* base, I index, M m, F v) {
    _mm512_mask_i32scatter_ps(base, m, index, v, 4);
  }
  MSF_SIMD_INLINE static void scatteri(std::int32_t* base, I index, M m, I v) {
    _mm512_mask_i32scatter_epi32(base, m, index, v, 4);
  }
  MSF_SIMD_INLINE static unsigned orLanes(I a) { return static_cast<unsigned>(_mm512_reduce_or_epi32(a)); }
  MSF_SIMD_INLINE static F set1(float x) { return _mm512_set1_ps(x); }
  MSF_SIMD_INLINE static I set1i(int x) { return _mm512_set1_epi32(x); }
  MSF_SIMD_INLINE static F xLanes() { return _mm512_setr_ps(0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3); }
  MSF_SIMD_INLINE static F yLanes() { return _mm512_setr_ps(0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3); }
  MSF_SIMD_INLINE static I voxelLanes() {
    return _mm512_setr_epi32(0, 1, 2, 3, 8, 9, 10, 11, 16, 17, 18, 19, 24, 25, 26, 27);
  }
  MSF_SIMD_INLINE static F add(F a, F b) { return _mm512_add_ps(a, b); }
  MSF_SIMD_INLINE static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
  MSF_SIMD_INLINE static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
  MSF_SIMD_INLINE static F div(F a, F b) { return _mm512_div_ps(a, b); }
  MSF_SIMD_INLINE static F max(F a, F b) { return _mm512_max_ps(a, b); }
  MSF_SIMD_INLINE static F min(F a, F b) { return _mm512_min_ps(a, b); }
  MSF_SIMD_INLINE static M ge(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
  MSF_SIMD_INLINE static M gt(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
  MSF_SIMD_INLINE static M le(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
  MSF_SIMD_INLINE static M lt(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
  MSF_SIMD_INLINE static M and_(M a, M b) { return static_cast<M>(a & b); }
  MSF_SIMD_INLINE static unsigned bits(M m) { return m; }
  MSF_SIMD_INLINE static I cvtt(F a) { return _mm512_cvttps_epi32(a); }
  MSF_SIMD_INLINE static I addi(I a, I b) { return _mm512_add_epi32(a, b); }
  MSF_SIMD_INLINE static I mullo(I a, I b) { return _mm512_mullo_epi32(a, b); }
  MSF_SIMD_INLINE static I times5(I a) { return _mm512_add_epi32(a, _mm512_slli_epi32(a, 2)); }
  MSF_SIMD_INLINE static F gather(const float* base, I index) { return _mm512_i32gather_ps(index, base, 4); }
  /// Compressed in a register, then stored whole: a compressing store to memory is slow on Zen 4.
  struct Compress {
    M lanes;
    MSF_SIMD_INLINE explicit Compress(unsigned m) : lanes(static_cast<M>(m)) {}
    MSF_SIMD_INLINE void store(float* dst, F v) const { _mm512_storeu_ps(dst, _mm512_maskz_compress_ps(lanes, v)); }
    MSF_SIMD_INLINE void store(std::int32_t* dst, I v) const {
      _mm512_storeu_si512(dst, _mm512_maskz_compress_epi32(lanes, v));
    }
    /// As 16-bit values (v's lanes in 0 .. 65535).
    MSF_SIMD_INLINE void store16(std::uint16_t* dst, I v) const {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst),
                          _mm512_cvtepi32_epi16(_mm512_maskz_compress_epi32(lanes, v)));
    }
  };
};

#include "voxel_test_body.h"
#include "voxel_update_body.h"

int run(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz, VoxelCandidates& out, int count) {
  return testSubBlock<V>(f, b, sx, sy, sz, out, count);
}

VoxelUpdateResult update(const VoxelUpdateFrame& f, const VoxelCandidates& c, int count, TsdfVoxel* voxels,
                         std::uint16_t* listed_index, float* listed_sdf) {
  return updateBlock<V>(f, c, count, voxels, listed_index, listed_sdf);
}

} // namespace
} // namespace avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options

BlockUpdate blockUpdateAvx2() { return subBlockTestAvx2() ? avx2::update : nullptr; }
BlockUpdate blockUpdateAvx512() { return subBlockTestAvx512() ? avx512::update : nullptr; }

SubBlockTest subBlockTestAvx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt") ? avx2::run : nullptr;
}

SubBlockTest subBlockTestAvx512() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt")
             ? avx512::run
             : nullptr;
}

#else // not x86: the portable kernel only

BlockUpdate blockUpdateAvx2() { return subBlockTestAvx2() ? avx2::update : nullptr; }
BlockUpdate blockUpdateAvx512() { return subBlockTestAvx512() ? avx512::update : nullptr; }

SubBlockTest subBlockTestAvx2() { return nullptr; }
BlockUpdate blockUpdateAvx2() { return nullptr; }
BlockUpdate blockUpdateAvx512() { return nullptr; }
SubBlockTest subBlockTestAvx512() { return nullptr; }

#endif

} // namespace msf::detail
