// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Analytic slices: what each interpolant must reproduce exactly, and what must stay empty.
#include <msf/common/exceptions.h>
#include <msf/range_image/slice_interpolation.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

struct Slice {
  std::vector<float> out;
  std::vector<std::uint8_t> gap;
};

Slice run(const std::vector<float>& in, const msf::SliceParams& p) {
  Slice s{std::vector<float>(in.size(), -1.f), std::vector<std::uint8_t>(in.size(), 99)};
  msf::interpolateSlice(in.data(), 1, static_cast<int>(in.size()), p, s.out.data(), s.gap.data());
  return s;
}

msf::SliceParams plain(msf::SliceInterpolant interpolant) {
  msf::SliceParams p;
  p.interpolant = interpolant;
  p.inverse_depth = false; // the paper's interpolation of z itself
  p.max_gap_px = 32;
  p.jump_abs_m = 100.f;    // no edges in these slices
  p.jump_inv_per_m = 100.f;
  return p;
}

TEST(SliceInterpolation, LinearReproducesALinearRampExactly) {
  // z = 5 + 0.25 i sampled at i = 0, 9, 20: every pixel between is on the ramp.
  std::vector<float> in(21, 0.f);
  for (int i : {0, 9, 20})
    in[i] = 5.f + 0.25f * static_cast<float>(i);
  const Slice s = run(in, plain(msf::SliceInterpolant::Linear));
  for (int i = 0; i <= 20; ++i)
    EXPECT_NEAR(s.out[i], 5.f + 0.25f * static_cast<float>(i), 1e-5f) << "pixel " << i;
  EXPECT_EQ(s.gap[0], 0);
  EXPECT_EQ(s.gap[9], 0);
  EXPECT_EQ(s.gap[4], 8);  // 8 empty pixels between 0 and 9
  EXPECT_EQ(s.gap[15], 10);
}

TEST(SliceInterpolation, CubicIsTheZeroSlopeHermiteStep) {
  // Between z0 = 2 at 0 and z1 = 12 at 10: z0 + (z1 - z0)(3t^2 - 2t^3), t = i / 10.
  std::vector<float> in(11, 0.f);
  in[0] = 2.f;
  in[10] = 12.f;
  const Slice s = run(in, plain(msf::SliceInterpolant::Cubic));
  for (int i = 0; i <= 10; ++i) {
    const double t = i / 10.0;
    EXPECT_NEAR(s.out[i], 2.0 + 10.0 * (3 * t * t - 2 * t * t * t), 1e-5) << "pixel " << i;
  }
  // Zero end slopes: the first step is much smaller than the linear one (1.0).
  EXPECT_LT(s.out[1] - s.out[0], 0.3f);
  EXPECT_LT(s.out[10] - s.out[9], 0.3f);
  EXPECT_NEAR(s.out[5], 7.f, 1e-5f); // symmetric about the middle
}

TEST(SliceInterpolation, CubicWeightsFollowAlphaAndBeta) {
  msf::SliceParams p = plain(msf::SliceInterpolant::Cubic);
  p.cubic_alpha = 1.f; // beta t^2 - alpha t^3 = 2t^2 - t^3
  p.cubic_beta = 2.f;
  std::vector<float> in(5, 0.f);
  in[0] = 1.f;
  in[4] = 3.f;
  const Slice s = run(in, p);
  const double t = 0.25;
  EXPECT_NEAR(s.out[1], 1.0 + 2.0 * (2 * t * t - t * t * t), 1e-6);
}

TEST(SliceInterpolation, CompoundTakesTheCubicForShortGapsAndLinearForLongOnes) {
  msf::SliceParams p = plain(msf::SliceInterpolant::Compound);
  p.short_gap_px = 4;
  // gap of 3 (cubic) then a gap of 7 (linear).
  std::vector<float> in(13, 0.f);
  in[0] = 10.f;
  in[4] = 14.f;
  in[12] = 22.f;
  const Slice s = run(in, p);
  const double t = 1 / 4.0;
  EXPECT_NEAR(s.out[1], 10.0 + 4.0 * (3 * t * t - 2 * t * t * t), 1e-5);
  for (int i = 5; i < 12; ++i)
    EXPECT_NEAR(s.out[i], 14.f + static_cast<float>(i - 4), 1e-5f) << "pixel " << i;
}

TEST(SliceInterpolation, InverseDepthReproducesAPlaneExactly) {
  // Along an image row a plane has 1/z affine in u: 1/z = 0.05 + 0.004 u.
  msf::SliceParams p = plain(msf::SliceInterpolant::Linear);
  p.inverse_depth = true;
  std::vector<float> in(31, 0.f);
  auto plane = [](int u) { return 1.f / (0.05f + 0.004f * static_cast<float>(u)); };
  in[0] = plane(0);
  in[30] = plane(30);
  const Slice s = run(in, p);
  for (int u = 0; u <= 30; ++u)
    EXPECT_NEAR(s.out[u], plane(u), 1e-4f * plane(u)) << "pixel " << u;
}

TEST(SliceInterpolation, GapsLongerThanTheMaximumStayEmpty) {
  msf::SliceParams p = plain(msf::SliceInterpolant::Linear);
  p.max_gap_px = 5;
  std::vector<float> in(20, 0.f);
  in[0] = 3.f;
  in[6] = 3.f;  // 5 empty: bridged
  in[13] = 3.f; // 6 empty: not bridged
  const Slice s = run(in, p);
  for (int i = 1; i < 6; ++i)
    EXPECT_FLOAT_EQ(s.out[i], 3.f);
  for (int i = 7; i < 13; ++i) {
    EXPECT_EQ(s.out[i], 0.f) << "pixel " << i;
    EXPECT_EQ(s.gap[i], 0) << "pixel " << i;
  }
  for (int i = 14; i < 20; ++i) // nothing after the last sample: no extrapolation
    EXPECT_EQ(s.out[i], 0.f);
}

TEST(SliceInterpolation, ADepthJumpIsAnEdgeAndStaysEmpty) {
  msf::SliceParams p = plain(msf::SliceInterpolant::Linear);
  p.jump_abs_m = 0.5f;
  p.jump_rel = 0.f;
  p.jump_inv_per_m = 0.03f; // 1/10 - 1/20 = 0.05 > 0.03: an edge
  std::vector<float> in(10, 0.f);
  in[0] = 10.f;
  in[4] = 20.f;
  in[9] = 21.f; // 1/20 - 1/21 = 0.0024: the same surface
  const Slice s = run(in, p);
  for (int i = 1; i < 4; ++i)
    EXPECT_EQ(s.out[i], 0.f) << "pixel " << i;
  for (int i = 5; i < 9; ++i)
    EXPECT_GT(s.out[i], 20.f) << "pixel " << i;
}

TEST(SliceInterpolation, WithoutTheEdgeTestEveryGapIsBridged) {
  // The paper's slices: the gap between 10 m and 20 m is bridged like any other.
  msf::SliceParams p = plain(msf::SliceInterpolant::Linear);
  p.jump_abs_m = 0.5f;
  p.jump_inv_per_m = 0.03f;
  p.edge_test = false;
  p.inverse_depth = false;
  EXPECT_FALSE(msf::isDepthJump(10.f, 20.f, p));
  std::vector<float> in(5, 0.f);
  in[0] = 10.f;
  in[4] = 20.f;
  const Slice s = run(in, p);
  for (int i = 1; i < 4; ++i)
    EXPECT_FLOAT_EQ(s.out[i], 10.f + 2.5f * static_cast<float>(i)) << "pixel " << i; // linear in z
}

TEST(SliceInterpolation, EdgeTestNeedsEveryThresholdExceeded) {
  msf::SliceParams p;
  p.jump_abs_m = 1.f;
  p.jump_rel = 0.f;
  p.jump_inv_per_m = 0.f;
  EXPECT_TRUE(msf::isDepthJump(2.f, 3.5f, p));
  EXPECT_FALSE(msf::isDepthJump(2.f, 2.9f, p)); // below the absolute threshold
  p.jump_rel = 0.5f;
  EXPECT_FALSE(msf::isDepthJump(4.f, 5.5f, p)); // 1.5 m < 0.5 * 4 m
  EXPECT_TRUE(msf::isDepthJump(4.f, 6.5f, p));
  p.jump_inv_per_m = 0.1f;
  EXPECT_FALSE(msf::isDepthJump(4.f, 6.5f, p)); // 1/4 - 1/6.5 = 0.096 < 0.1
  EXPECT_TRUE(msf::isDepthJump(4.f, 7.f, p));
}

TEST(SliceInterpolation, SamplesAreKeptAndNanIsEmpty) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> in{nan, 4.f, nan, nan, 6.f, -1.f};
  const Slice s = run(in, plain(msf::SliceInterpolant::Linear));
  EXPECT_EQ(s.out[0], 0.f);
  EXPECT_EQ(s.out[1], 4.f);
  EXPECT_EQ(s.out[4], 6.f);
  EXPECT_NEAR(s.out[2], 4.f + 2.f / 3.f, 1e-5f);
  EXPECT_EQ(s.out[5], 0.f); // negative depth is no sample
}

TEST(SliceInterpolation, StridedSliceEqualsContiguousOne) {
  // A column of a 3-wide image: stride 3.
  const std::vector<float> column{7.f, 0.f, 0.f, 0.f, 9.f, 0.f, 12.f};
  std::vector<float> image(column.size() * 3, 0.f);
  for (std::size_t i = 0; i < column.size(); ++i)
    image[i * 3 + 1] = column[i];
  std::vector<float> out(image.size(), -1.f);
  std::vector<std::uint8_t> gap(image.size(), 99);
  const msf::SliceParams p = plain(msf::SliceInterpolant::Compound);
  msf::interpolateSlice(image.data() + 1, 3, static_cast<int>(column.size()), p, out.data() + 1, gap.data() + 1);
  const Slice ref = run(column, p);
  for (std::size_t i = 0; i < column.size(); ++i) {
    EXPECT_EQ(out[i * 3 + 1], ref.out[i]);
    EXPECT_EQ(gap[i * 3 + 1], ref.gap[i]);
    EXPECT_EQ(out[i * 3], -1.f); // neighbours untouched
  }
}

TEST(SliceInterpolation, NamesParseAndBadNamesAreErrors) {
  EXPECT_EQ(msf::parseSliceInterpolant("compound"), msf::SliceInterpolant::Compound);
  EXPECT_EQ(msf::parseSliceInterpolant("linear"), msf::SliceInterpolant::Linear);
  EXPECT_EQ(msf::parseSliceInterpolant("cubic"), msf::SliceInterpolant::Cubic);
  try {
    msf::parseSliceInterpolant("spline");
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("spline"), std::string::npos);
  }
}

} // namespace
