// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The portable kernel of SemiGlobalMatcher: semi_global_kernel_body.h over 8 int16 lanes (one
// SSE2 or NEON register), each operation that of the AVX2 instruction the vector kernel uses,
// lane for lane (saturation, unsigned comparisons and the order of the disparities included),
// so that its result is the vector kernels' to the bit (the body's result does not depend on
// the number of lanes). It runs where the CPU has no AVX2.
#include "semi_global_kernel.h"
#include "semi_global_layout.h"

#include <cstring>

// Its vectors never cross a call that is not inlined, so their ABI does not matter.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace msf::detail {

#define MSF_SIMD __attribute__((noinline))
#define MSF_SIMD_INLINE __attribute__((always_inline)) inline
// Not unrolled: a vector here is two or more registers, and unrolled loops take the register
// allocator minutes.
#define MSF_SIMD_UNROLL(n)

namespace portable {
namespace {

// GCC's generic vectors: each operation one statement that the compiler lowers to the vector
// instructions the target has (SSE2 on any x86-64), rather than a loop over the lanes for its
// vectoriser to find again.
using I16 = std::int16_t __attribute__((vector_size(16)));
using U16 = std::uint16_t __attribute__((vector_size(16)));
using U8 = std::uint8_t __attribute__((vector_size(16)));
using U8Half = std::uint8_t __attribute__((vector_size(8)));

/// 8 x int16 (16 x uint8).
struct V {
  using Reg = I16;
  static constexpr int kLanes = 8;
  static constexpr int kMaskBitsPerLane = 1;
  /// One row matcher for any number of vectors: a copy per number, as the vector kernels
  /// have, would take minutes to compile for no gain that matters in a fallback.
  static constexpr bool kUnrolled = false;

  MSF_SIMD_INLINE static U16 u(Reg a) { return reinterpret_cast<U16>(a); }
  MSF_SIMD_INLINE static U8 bytes(Reg a) { return reinterpret_cast<U8>(a); }
  MSF_SIMD_INLINE static Reg lanes(U16 a) { return reinterpret_cast<Reg>(a); }
  MSF_SIMD_INLINE static Reg lanes(U8 a) { return reinterpret_cast<Reg>(a); }
  /// The wrapped sum (or difference) `wrapped` of a and b, saturated where it overflowed:
  /// where a and b (b negated for a difference) have one sign and the result the other.
  MSF_SIMD_INLINE static Reg saturated(Reg wrapped, Reg a, Reg b_signed) {
    const Reg overflow = ((a ^ wrapped) & (b_signed ^ wrapped)) < 0;
    return overflow ? (a < 0 ? set16(-0x8000) : set16(0x7FFF)) : wrapped;
  }

  MSF_SIMD_INLINE static Reg load(const void* p) {
    Reg r;
    std::memcpy(&r, p, sizeof r);
    return r;
  }
  MSF_SIMD_INLINE static void store(void* p, Reg v) { std::memcpy(p, &v, sizeof v); }
  MSF_SIMD_INLINE static Reg set16(int v) { return Reg{} + static_cast<std::int16_t>(v); }
  MSF_SIMD_INLINE static Reg set8(int v) { return lanes(U8{} + static_cast<std::uint8_t>(v)); }
  MSF_SIMD_INLINE static Reg add16(Reg a, Reg b) { return lanes(u(a) + u(b)); }
  MSF_SIMD_INLINE static Reg adds16(Reg a, Reg b) { return saturated(add16(a, b), a, b); }
  MSF_SIMD_INLINE static Reg sub16(Reg a, Reg b) { return lanes(u(a) - u(b)); }
  MSF_SIMD_INLINE static Reg subs16(Reg a, Reg b) { return saturated(sub16(a, b), a, ~b); }
  MSF_SIMD_INLINE static Reg min16(Reg a, Reg b) { return a < b ? a : b; }
  MSF_SIMD_INLINE static Reg max16(Reg a, Reg b) { return a > b ? a : b; }
  /// |a| with -32768 staying 0x8000, as vpabsw.
  MSF_SIMD_INLINE static Reg abs16(Reg a) { return a < 0 ? lanes(U16{} - u(a)) : a; }
  MSF_SIMD_INLINE static Reg minu16(Reg a, Reg b) { return u(a) < u(b) ? a : b; }
  MSF_SIMD_INLINE static Reg sixteenthU16(Reg a) { return lanes(u(a) >> 4); }
  MSF_SIMD_INLINE static Reg mullo16(Reg a, Reg b) { return lanes(u(a) * u(b)); }
  MSF_SIMD_INLINE static Reg and_(Reg a, Reg b) { return a & b; }
  MSF_SIMD_INLINE static Reg subsu8(Reg a, Reg b) {
    const U8 x = bytes(a), y = bytes(b);
    return lanes(x > y ? x - y : U8{});
  }
  MSF_SIMD_INLINE static Reg maxu8(Reg a, Reg b) { return lanes(bytes(a) > bytes(b) ? bytes(a) : bytes(b)); }
  MSF_SIMD_INLINE static Reg minu8(Reg a, Reg b) { return lanes(bytes(a) < bytes(b) ? bytes(a) : bytes(b)); }
  MSF_SIMD_INLINE static Reg addsu8(Reg a, Reg b) {
    const U8 sum = bytes(a) + bytes(b);
    return lanes(sum < bytes(a) ? U8{} + 0xFF : sum);
  }
  MSF_SIMD_INLINE static Reg quarterBytes(Reg a) { return lanes(bytes(a) >> 2); }
  /// L(d - 1) of `current`'s lanes, given the vector before it.
  MSF_SIMD_INLINE static Reg below(Reg previous, Reg current) {
    return __builtin_shuffle(previous, current, I16{7, 8, 9, 10, 11, 12, 13, 14});
  }
  /// L(d + 1) of `current`'s lanes, given the vector after it.
  MSF_SIMD_INLINE static Reg above(Reg current, Reg next) {
    return __builtin_shuffle(current, next, I16{1, 2, 3, 4, 5, 6, 7, 8});
  }
  /// Bytes 0..7 (`high`: 8..15) of a as int16 lanes.
  MSF_SIMD_INLINE static Reg lowBytes(Reg a) {
    U8Half half;
    std::memcpy(&half, &a, sizeof half);
    return __builtin_convertvector(half, Reg);
  }
  MSF_SIMD_INLINE static Reg highBytes(Reg a) {
    U8Half half;
    std::memcpy(&half, reinterpret_cast<const char*>(&a) + sizeof half, sizeof half);
    return __builtin_convertvector(half, Reg);
  }
  /// a - b of 16 bytes as int16, disparities 0..7 in `low` and 8..15 in `high`.
  MSF_SIMD_INLINE static void widenDifference(Reg a, Reg b, Reg& low, Reg& high) {
    low = lowBytes(a) - lowBytes(b);
    high = highBytes(a) - highBytes(b);
  }
  MSF_SIMD_INLINE static void widen(Reg a, Reg& low, Reg& high) {
    low = lowBytes(a);
    high = highBytes(a);
  }
  /// Smallest of the lanes as unsigned 16-bit values (all non-negative where it is used): a
  /// tree of minima over the lanes halved, quartered and paired.
  MSF_SIMD_INLINE static int horizontalMin(Reg v) {
    v = minu16(v, __builtin_shuffle(v, I16{4, 5, 6, 7, 0, 1, 2, 3}));
    v = minu16(v, __builtin_shuffle(v, I16{2, 3, 0, 1, 6, 7, 4, 5}));
    v = minu16(v, __builtin_shuffle(v, I16{1, 0, 3, 2, 5, 4, 7, 6}));
    return u(v)[0];
  }
  /// `candidate` where a < b, else `current`.
  MSF_SIMD_INLINE static Reg whereLess(Reg a, Reg b, Reg candidate, Reg current) { return a < b ? candidate : current; }
  /// `candidate` where a == b, else `current`.
  MSF_SIMD_INLINE static Reg whereEqual(Reg a, Reg b, Reg candidate, Reg current) {
    return a == b ? candidate : current;
  }
  MSF_SIMD_INLINE static Reg laneIndex() { return Reg{0, 1, 2, 3, 4, 5, 6, 7}; }
  /// One bit per lane where a <= limit.
  MSF_SIMD_INLINE static unsigned long long atMostMask(Reg a, Reg limit) {
    const Reg at_most = a <= limit;
    unsigned long long mask = 0;
    for (int i = 0; i < kLanes; ++i)
      mask |= static_cast<unsigned long long>(at_most[i] != 0) << i;
    return mask;
  }
};

#include "semi_global_kernel_body.h"

} // namespace
} // namespace portable

void sgmStripPortable(const SgmStrip& strip) { portable::runStrip(strip); }

} // namespace msf::detail
