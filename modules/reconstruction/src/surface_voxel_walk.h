// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/tsdf_block.h>

#include <Eigen/Geometry>

#include <cstdint>

namespace msf::detail {

/// Calls free(voxel, p) for each observed voxel of `block` behind a surface (sdf < 0), in the
/// sub-blocks flagged as holding one, with p its centre in the frame of `T_frame_world`; free
/// returns whether it changed the voxel. A changed block gets its signs and `stamp`. This is
/// the walk of every carving: only voxels behind a surface can be cleared.
template <class Free>
void carveSurfaceVoxels(TsdfBlock& block, const Eigen::Isometry3f& T_frame_world, float voxel_size,
                        std::uint64_t stamp, Free&& free) {
  const Eigen::Vector3f origin = T_frame_world * (block.origin().cast<float>() * voxel_size);
  const Eigen::Matrix3f axes = T_frame_world.linear() * voxel_size;
  bool changed = false;
  for (int sub = 0; sub < 8; ++sub) {
    if (!(block.negative_subblocks & (1u << sub)))
      continue;
    const int sx = 4 * (sub & 1), sy = 2 * (sub & 2), sz = sub & 4;
    for (int z = sz; z < sz + 4; ++z)
      for (int y = sy; y < sy + 4; ++y)
        for (int x = sx; x < sx + 4; ++x) {
          TsdfVoxel& voxel = block.at(x, y, z);
          if (!(voxel.sdf < 0.f && voxel.weight > 0.f))
            continue;
          const Eigen::Vector3f p =
              origin + axes * Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
          changed |= free(voxel, p);
        }
  }
  if (changed) {
    block.updateSigns();
    block.stamp = stamp;
  }
}

} // namespace msf::detail
