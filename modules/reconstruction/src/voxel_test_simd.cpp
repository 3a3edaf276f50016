// The wide voxel tests (see voxel_test.h): the portable kernel's float operations, lane for
// lane and in the same order, on two rows of a sub-block at once (AVX2, 8 lanes) or four (AVX-512,
// 16), with gathers for the pixels' depths and bands and compressing stores for the candidates.
// Only the code between the target pragmas uses those instruction sets, so this file builds for
// any x86-64 and the caller picks a kernel at run time. Built with -ffp-contract=off: an FMA
// would round X, u or v differently from the portable kernel, and move voxels across pixels.
#include "voxel_test.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MSF_VOXEL_TEST_X86 1
#endif

#include <array>

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
  };
};

#include "voxel_test_body.h"

int run(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz, VoxelCandidates& out, int count) {
  return testSubBlock<V>(f, b, sx, sy, sz, out, count);
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
  };
};

#include "voxel_test_body.h"

int run(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz, VoxelCandidates& out, int count) {
  return testSubBlock<V>(f, b, sx, sy, sz, out, count);
}

} // namespace
} // namespace avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options

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

SubBlockTest subBlockTestAvx2() { return nullptr; }
SubBlockTest subBlockTestAvx512() { return nullptr; }

#endif

} // namespace msf::detail
