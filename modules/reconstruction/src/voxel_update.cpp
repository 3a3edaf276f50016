// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The portable update of a block's candidates (see voxel_update.h) and the choice of a kernel.
#include "voxel_update.h"

#include <cmath>
#include <cstddef>

namespace msf::detail {

VoxelUpdateResult blockUpdatePortable(const VoxelUpdateFrame& f, const VoxelCandidates& candidates, int count,
                                      TsdfVoxel* voxels, std::uint16_t* listed_index, float* listed_sdf) {
  const int width = f.width, height = f.height;
  const float trunc = f.trunc, vs = f.voxel_size;
  VoxelUpdateResult out;
  for (int c = 0; c < count; ++c) {
    const float u = candidates.u[c], v = candidates.v[c], z = candidates.z[c];
    const int ui = candidates.ui[c], vi = candidates.vi[c];
    const auto voxel_index = static_cast<std::uint16_t>(candidates.voxel[c]);
    float d = candidates.nearest[c];
    float quad_min = d; // the least depth of the 4 pixels around the projection
    const PixelBand& pixel = f.pixels[candidates.pixel[c]];
    const float scale = pixel.scale;
    const int u0 = static_cast<int>(u), v0 = static_cast<int>(v); // u, v > -0.5: floor for >= 0
    if (u >= 0.f && v >= 0.f && u0 + 1 < width && v0 + 1 < height) {
      const float* r0 = f.depth + v0 * width + u0;
      const float* r1 = r0 + width;
      const float d00 = r0[0], d10 = r0[1], d01 = r1[0], d11 = r1[1];
      const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
      const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
      quad_min = lo;
      // Only where the 4 agree: across a depth edge, a blend would be a phantom surface.
      if (f.bilinear && lo > 0.f && hi - lo < pixel.behind) {
        const float a = u - static_cast<float>(u0), b = v - static_cast<float>(v0);
        d = (d00 * (1 - a) + d10 * a) * (1 - b) + (d01 * (1 - a) + d11 * a) * b;
      }
    }
    const float diff = d - z, band = pixel.front, behind = pixel.behind;
    if (diff < -behind)
      continue;
    const bool in_band = diff <= band;
    // Free space only where all 4 pixels around the projection see past the band: beside a
    // depth edge the nearest pixel may see the background through a foreground voxel.
    if (!in_band && !(f.carving && quad_min > 0.f && quad_min - z > band))
      continue;
    // In front of the band: free space. A band widened for noise reaches beyond the
    // truncation, the values stay within it (what a truncated distance is).
    const float sdf = std::clamp((in_band ? diff : band) * scale, -trunc, trunc);
    // The pixel's inverse variance of the depth along the ray. (The plane distance's is
    // 1 / scale^2 times larger, but weighting by it let grazing views of noisy far stereo
    // outweigh the rest: on the synthetic street, 0.145 m mesh accuracy against 0.043 m at
    // the same min_weight, and a worse accuracy at every completeness.)
    if (!(pixel.weight > 0.f))
      continue;
    float w = in_band ? pixel.weight : pixel.free; // free space: carving_weight of the evidence
    if (in_band && f.dropoff && sdf < -vs && behind * scale > vs)
      w *= (behind * scale + sdf) / (behind * scale - vs); // behind the surface the observation is a guess
    if (!(w > 0.f))
      continue; // at the band's far end the drop-off leaves nothing
    // Colour only near the surface: the mesh's vertices take it from the voxels on either side.
    const bool coloured = f.color && in_band && std::abs(sdf) < f.colour_band;
    const std::uint8_t* bgr = coloured ? f.color + static_cast<std::ptrdiff_t>(vi) * f.color_step + 3 * ui : nullptr;
    TsdfVoxel& voxel = voxels[voxel_index];
    updateVoxel(voxel, sdf, w, bgr, f.max_weight, trunc, passedThrough(f, quad_min - z, pixel.weight));
    out.signs |= voxel.sdf < 0.f ? TsdfBlock::kHasNegative : TsdfBlock::kHasPositive;
    out.negative |= voxel.sdf < 0.f ? static_cast<std::uint8_t>(1u << TsdfBlock::subBlockOf(voxel_index)) : 0;
    if (f.regularized && std::abs(voxel.sdf) < f.smooth_band) {
      listed_index[out.listed] = voxel_index;
      listed_sdf[out.listed] = voxel.sdf;
      ++out.listed;
    }
    ++out.updated;
  }
  return out;
}

BlockUpdate blockUpdate() {
  switch (TsdfIntegrator::voxelTestLanes()) {
  case 16: return blockUpdateAvx512();
  case 8: return blockUpdateAvx2();
  default: return blockUpdatePortable;
  }
}

} // namespace msf::detail
