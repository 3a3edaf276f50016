// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/spatial_hash.h>
#include <msf/reconstruction/tsdf_voxel.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>

namespace msf {

/// Integer coordinates of a block (or of a voxel) on the volume's grid.
using GridIndex = Eigen::Vector3i;

/// Hash of a GridIndex for sets and maps of blocks (the mesher's cache, ScanBandBlocks).
struct GridIndexHash {
  std::size_t operator()(const GridIndex& i) const noexcept { return spatialHash32(i.x(), i.y(), i.z()); }
};

/// A dense cube of kSide^3 voxels, the unit of allocation, of parallel work and of
/// incremental meshing (Voxblox's Block). Voxels are contiguous, x fastest.
struct TsdfBlock {
  static constexpr int kSide = 8;
  static constexpr int kVoxels = kSide * kSide * kSide;

  GridIndex index{0, 0, 0};      ///< block coordinates: voxel v lies in block floor(v / kSide)
  std::uint64_t stamp = 0;       ///< volume generation of the last change (see TsdfVolume)
  /// Bit 0: an observed voxel has (or had) sdf >= 0; bit 1: one has (or had) sdf < 0, so that
  /// the mesher skips blocks a surface cannot cross. A bit may stay set after the voxels
  /// changed (the integrator only sets bits, cheaply): that costs the mesher a look, never a
  /// triangle. Code that writes voxels directly sets them too, e.g. with updateSigns().
  std::uint8_t signs = 0;
  /// Bit k: sub-block k (the 4^3 voxels at 4 * (k & 1, k >> 1 & 1, k >> 2 & 1)) holds (or held)
  /// an observed voxel with sdf < 0, a surface that free space may have to carve away; set like
  /// `signs`.
  std::uint8_t negative_subblocks = 0;
  std::array<TsdfVoxel, kVoxels> voxels{};

  static constexpr std::uint8_t kHasPositive = 1, kHasNegative = 2;
  /// The sub-block of voxel `linear` (see negative_subblocks).
  static constexpr int subBlockOf(int linear) {
    return ((linear >> 2) & 1) | (((linear >> 5) & 1) << 1) | (((linear >> 8) & 1) << 2);
  }
  void updateSigns() {
    std::uint8_t s = 0, negative = 0;
    for (int i = 0; i < kVoxels; ++i)
      if (voxels[i].weight > 0.f) {
        s |= voxels[i].sdf < 0.f ? kHasNegative : kHasPositive;
        negative |= voxels[i].sdf < 0.f ? static_cast<std::uint8_t>(1u << subBlockOf(i)) : 0;
      }
    signs = s;
    negative_subblocks = negative;
  }

  static constexpr int linear(int x, int y, int z) { return x + kSide * (y + kSide * z); }
  TsdfVoxel& at(int x, int y, int z) { return voxels[linear(x, y, z)]; }
  const TsdfVoxel& at(int x, int y, int z) const { return voxels[linear(x, y, z)]; }
  /// Global index of the block's first voxel.
  GridIndex origin() const { return index * kSide; }
};

/// floor(a / b) for b > 0, also for negative a.
inline int floorDiv(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }

/// The block that holds global voxel v.
inline GridIndex blockOf(const GridIndex& v) {
  return {floorDiv(v.x(), TsdfBlock::kSide), floorDiv(v.y(), TsdfBlock::kSide), floorDiv(v.z(), TsdfBlock::kSide)};
}

} // namespace msf
