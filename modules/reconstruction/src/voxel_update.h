// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The update of the voxels that passed TsdfIntegrator::integrate's voxel test, a block at a
// time: a portable kernel (one candidate at a time) and, on x86-64, AVX2 (8) and AVX-512 (16)
// ones in voxel_test_simd.cpp, picked with the test's (TsdfIntegrator::voxelTestLanes). Every
// kernel does the same float operations per candidate in the same order, so all give the same
// voxels, bit for bit.
#pragma once

#include "voxel_test.h"

#include <algorithm>

namespace msf::detail {

/// Running weighted mean of one observation into a voxel (the portable kernel's, and the scan's);
/// `passed`: its ray passed through the voxel, which TsdfVoxel::passes counts (else resets, and
/// a voxel passed before has TsdfVoxel::reappeared).
inline void updateVoxel(TsdfVoxel& voxel, float sdf, float w, const std::uint8_t* bgr, float max_weight, float trunc,
                        bool passed) {
  const float total = voxel.weight + w;
  const float inv = 1.f / total;
  // Clamped: rounding may carry a mean of values at the truncation a hair past it.
  voxel.sdf = std::clamp((voxel.sdf * voxel.weight + sdf * w) * inv, -trunc, trunc);
  if (bgr) {
    voxel.r = static_cast<std::uint8_t>((voxel.r * voxel.weight + bgr[2] * w) * inv + 0.5f);
    voxel.g = static_cast<std::uint8_t>((voxel.g * voxel.weight + bgr[1] * w) * inv + 0.5f);
    voxel.b = static_cast<std::uint8_t>((voxel.b * voxel.weight + bgr[0] * w) * inv + 0.5f);
  }
  voxel.weight = std::min(total, max_weight);
  const int passes = passed ? std::min(voxel.passes() + 1, TsdfVoxel::kMaxPasses) : 0;
  const std::uint8_t reappeared = !passed && voxel.passes() > 0 ? TsdfVoxel::kReappeared : 0;
  voxel.flags = static_cast<std::uint8_t>((voxel.flags & ~TsdfVoxel::kPassesMask) | passes << TsdfVoxel::kPassesShift |
                                          reappeared);
}

/// What the update reads of a frame and of the integrator's settings.
struct VoxelUpdateFrame {
  int width, height;
  const float* depth;        ///< rows of `width` (one index with pixels)
  const PixelBand* pixels;
  const std::uint8_t* color; ///< BGR rows of `color_step` bytes, at least 2 pixels wide; null: none
  int color_step;
  bool bilinear, carving, dropoff, regularized;
  float trunc, voxel_size, colour_band, max_weight, smooth_band;
  /// Squared sigmas of a pixel's depth that a voxel must lie in front of it (and more than the
  /// truncation) for its ray to have passed through the voxel (TsdfVoxel::passes).
  float pass_sigmas2;
};

/// Whether the rays passed a voxel that lies `ahead` in front of the least depth of the 4 pixels
/// around its projection (along the ray; the pixel's weight `w`, its inverse variance): by more
/// than the truncation and than the depth's noise. All 4, as for free space: beside a depth edge
/// the nearest pixel may see the background past a foreground voxel. Along the ray, not the
/// plane distance: a voxel above a grazing road is near its plane.
inline bool passedThrough(const VoxelUpdateFrame& f, float ahead, float w) {
  return ahead > f.trunc && ahead * ahead * w > f.pass_sigmas2;
}

/// The block's updated voxels, and (when regularized) those within smooth_band of a surface.
struct VoxelUpdateResult {
  int updated = 0, listed = 0;
  std::uint8_t signs = 0, negative = 0; ///< as TsdfBlock's
};

/// Room a block's list needs: its voxels and one vector more (wide kernels store whole vectors).
constexpr int kListStride = TsdfBlock::kVoxels + 16;

/// Updates the voxels of the `count` candidates of one block; lists the changed ones near a
/// surface in listed_index / listed_sdf (kListStride entries) when regularized.
using BlockUpdate = VoxelUpdateResult (*)(const VoxelUpdateFrame& frame, const VoxelCandidates& c, int count,
                                          TsdfVoxel* voxels, std::uint16_t* listed_index, float* listed_sdf);

VoxelUpdateResult blockUpdatePortable(const VoxelUpdateFrame&, const VoxelCandidates&, int, TsdfVoxel*,
                                      std::uint16_t*, float*);
/// Null where this build or this CPU has none.
BlockUpdate blockUpdateAvx2();
BlockUpdate blockUpdateAvx512();
/// The kernel of the width that subBlockTest() has.
BlockUpdate blockUpdate();

} // namespace msf::detail
