// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The nearest-pixel test of TsdfIntegrator::integrate's voxels, a 4^3 sub-block at a time: a
// portable kernel (4 lanes, GCC/Clang vector extensions) and, on x86-64, AVX2 (8 lanes: two
// rows of voxels) and AVX-512 (16: four rows) ones in voxel_test_simd.cpp, picked at run time.
// Every kernel does the same float operations per voxel in the same order, so all give the
// same candidates, bit for bit.
#pragma once

#include <msf/reconstruction/tsdf_block.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <cstddef>
#include <cstdint>

namespace msf::detail {

/// What the test reads of a frame. depth and pixels are rows of `width`, one index for both.
struct VoxelTestFrame {
  float fx, fy, cx, cy;
  int width, height;
  float min_d, max_d;
  bool carving;             ///< space carving: every voxel in front of the band passes
  const float* depth;
  const PixelBand* pixels;
};

/// A block in the camera frame: its voxel (0, 0, 0) at `base`, one voxel along x, y, z.
struct VoxelTestBlock {
  float base[3], ex[3], ey[3], ez[3];
  const TsdfVoxel* voxels; ///< prefetched where a row of voxels has a candidate
};

/// The voxels that passed, in the order (z, y, x), a field per array so that wide kernels store
/// a vector's passing lanes at once. Room for a block and one vector more (whole-vector stores).
struct VoxelCandidates {
  static constexpr int kCapacity = TsdfBlock::kVoxels + 16;
  alignas(64) float u[kCapacity], v[kCapacity], z[kCapacity], nearest[kCapacity];
  alignas(64) std::int32_t pixel[kCapacity]; ///< index of the nearest pixel (depth and pixels)
  alignas(64) std::int32_t ui[kCapacity], vi[kCapacity];
  alignas(64) std::int32_t voxel[kCapacity]; ///< index in the block
};

/// Tests the 64 voxels of the sub-block at voxel (sx, sy, sz) of the block, appends those that
/// pass to `out` from `count` on, and returns the new count.
using SubBlockTest = int (*)(const VoxelTestFrame& frame, const VoxelTestBlock& block, int sx, int sy, int sz,
                             VoxelCandidates& out, int count);

int subBlockTestPortable(const VoxelTestFrame&, const VoxelTestBlock&, int, int, int, VoxelCandidates&, int);
/// Null where this build or this CPU has none.
SubBlockTest subBlockTestAvx2();
SubBlockTest subBlockTestAvx512();
/// The widest kernel that the CPU runs and TsdfIntegrator::setMaxVoxelTestLanes allows.
SubBlockTest subBlockTest();

} // namespace msf::detail
