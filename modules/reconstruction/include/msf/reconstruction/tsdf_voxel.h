// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstdint>

namespace msf {

/// One voxel of a TSDF volume (as Voxblox's TsdfVoxel): signed distance to the nearest
/// surface along the viewing direction in metres (positive in front of the surface, in free
/// space; negative behind it), clamped to +-truncation; the accumulated weight (0 = never
/// observed); the weighted mean colour. 12 bytes, so a block of 8^3 voxels is 6 KiB.
struct TsdfVoxel {
  float sdf = 0.f;
  float weight = 0.f;
  std::uint8_t r = 0, g = 0, b = 0;
  std::uint8_t flags = 0; ///< internal to the integrator (regularization mask); 0 on disk

  bool observed() const { return weight > 0.f; }
};

static_assert(sizeof(TsdfVoxel) == 12, "TsdfVoxel is meant to stay 12 bytes");

} // namespace msf
