// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace msf {

/// How a gap between two consecutive samples of a slice is bridged.
enum class SliceInterpolant {
  Compound, ///< the paper's rule: cubic up to short_gap_px, linear up to max_gap_px
  Linear,   ///< linear (paper eq. 2) up to max_gap_px
  Cubic     ///< zero-slope cubic (paper eq. 3-5) up to max_gap_px
};

inline constexpr Choice<SliceInterpolant> kSliceInterpolants[] = {
    {"compound", SliceInterpolant::Compound}, {"linear", SliceInterpolant::Linear}, {"cubic", SliceInterpolant::Cubic}};

/// "compound", "linear", "cubic"; throws ConfigError naming the text otherwise.
SliceInterpolant parseSliceInterpolant(const std::string& name);
const char* toString(SliceInterpolant interpolant);

/// Parameters of one slice pass (a row or a column of a depth image): the first keys of
/// section `interpolation`.
struct SliceParams {
  SliceInterpolant interpolant = SliceInterpolant::Compound;
  int short_gap_px = 4;
  int max_gap_px = 64;
  /// Leave a gap open across an object edge (isDepthJump); false bridges every gap up to
  /// max_gap_px, as the paper does.
  bool edge_test = true;
  /// A gap is an object edge when its ends z0, z1 differ by more than all three jumps.
  float jump_abs_m = 0.5f;
  float jump_rel = 0.f;
  float jump_inv_per_m = 0.03f;
  float cubic_alpha = 2.f;
  float cubic_beta = 3.f;
  /// Interpolate 1/z, which is affine in the image along a plane (false: the paper's eq. 2-5 on z).
  bool inverse_depth = true;

  template <class Keys>
  void keys(Keys& k) {
    k("method", interpolant, kSliceInterpolants,
      "how a gap is bridged: compound (cubic up to short_gap_px, linear up to max_gap_px), linear or cubic");
    k("short_gap_px", short_gap_px, atLeast(0), "gaps of at most this many empty pixels take the cubic, px");
    k("max_gap_px", max_gap_px, atLeast(0), "longer gaps stay empty, px");
    k("edge_test", edge_test, "leave gaps across an object edge open (false: bridge every gap, as the paper)");
    k("jump_abs_m", jump_abs_m, atLeast(0), "an edge's ends differ by more than this, m,");
    k("jump_rel", jump_rel, atLeast(0), "and by more than this share of the nearer depth (0: off),");
    k("jump_inv_per_m", jump_inv_per_m, atLeast(0), "and by more than this in inverse depth |1/z0 - 1/z1|, 1/m");
    k("cubic_alpha", cubic_alpha, anyNumber(), "the cubic's weight beta t^2 - alpha t^3 (the paper: alpha 2, beta 3)");
    k("cubic_beta", cubic_beta, anyNumber(), "the cubic's beta");
    k("inverse_depth", inverse_depth, "interpolate 1/z, affine along a plane in the image (false: z, as the paper)");
  }
};

/// True when the ends z0, z1 of a gap are on two sides of an object edge (never without edge_test).
/// Inverse depth is affine in the image along a plane, so the ground's inverse depth
/// changes little across a gap even far away, where its depth changes a lot.
inline bool isDepthJump(float z0, float z1, const SliceParams& p) {
  const float d = z1 > z0 ? z1 - z0 : z0 - z1;
  const float nearer = z1 < z0 ? z1 : z0;
  return p.edge_test && d > p.jump_abs_m && d > p.jump_rel * nearer && d > p.jump_inv_per_m * z0 * z1;
}

/// Calls emit(k, z) with the estimate z of the k-th (1..empty) of the `empty` pixels
/// strictly between two samples z0 and z1 of a slice: the zero-slope cubic for short gaps
/// (compound) or always (cubic), else linear. The caller has checked the gap (its length,
/// the depth jump across it).
template <typename Emit>
inline void bridgeValues(float z0, float z1, int empty, const SliceParams& p, Emit&& emit) {
  const bool cubic = p.interpolant == SliceInterpolant::Cubic ||
                     (p.interpolant == SliceInterpolant::Compound && empty <= p.short_gap_px);
  const float a = p.inverse_depth ? 1.f / z0 : z0;
  const float delta = (p.inverse_depth ? 1.f / z1 : z1) - a;
  const float step = 1.f / static_cast<float>(empty + 1);
  // One loop per case, so that none branches inside (the common case: linear, 1/z).
  auto run = [&](auto weight, auto finish) {
    for (int k = 1; k <= empty; ++k)
      emit(k, finish(a + delta * weight(static_cast<float>(k) * step)));
  };
  auto linear = [](float t) { return t; };
  auto cubicWeight = [&](float t) { return t * t * (p.cubic_beta - p.cubic_alpha * t); }; // paper eq. 3-5
  auto inverse = [](float v) { return 1.f / v; };
  auto plain = [](float v) { return v; };
  if (cubic)
    p.inverse_depth ? run(cubicWeight, inverse) : run(cubicWeight, plain);
  else
    p.inverse_depth ? run(linear, inverse) : run(linear, plain);
}

/// The number of empty pixels of a gap, saturated to what a gap image holds.
inline std::uint8_t gapCode(int empty) { return static_cast<std::uint8_t>(empty < 255 ? empty : 255); }

/// Fills one slice of `n` pixels read at `in[i * stride]` (a sample is > 0; 0 or NaN is
/// empty) into `out[i * stride]` (0 where there is no estimate) and `gap[i * stride]` (the
/// number of empty pixels of the gap an estimate was bridged over, saturated at 255; 0 on a
/// sample and where there is no estimate). `in` and `out` may be the same array.
void interpolateSlice(const float* in, std::ptrdiff_t stride, int n, const SliceParams& params, float* out,
                      std::uint8_t* gap);

} // namespace msf
