// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The portable voxel test (see voxel_test.h) and the choice of a kernel.
#include "voxel_test.h"

#include <algorithm>
#include <atomic>

namespace msf {

namespace detail {

namespace {

// 4 lanes of SIMD (GCC and Clang vector extensions: SSE2 on x86-64, NEON on ARM), for the
// row of 4 voxels projected at once. Comparisons give 0 or -1 per lane.
using Float4 = float __attribute__((vector_size(16)));
using Int4 = std::int32_t __attribute__((vector_size(16)));

inline Float4 clamp4(Float4 v, float lo, float hi) {
  v = v > lo ? v : lo;
  return v < hi ? v : hi;
}

/// Bit k set when lane k is true (-1).
inline int laneMask(Int4 m) {
#ifdef __SSE__
  return __builtin_ia32_movmskps(reinterpret_cast<Float4>(m)); // one instruction
#else
  return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
}

} // namespace

int subBlockTestPortable(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz,
                         VoxelCandidates& out, int count) {
  const float* depth_data = f.depth;
  const PixelBand* pixel_data = f.pixels;
  const float width_f = static_cast<float>(f.width), height_f = static_cast<float>(f.height);
  for (int z = sz; z < sz + 4; ++z)
    for (int y = sy; y < sy + 4; ++y) {
      // A row of 4 voxels, projected and tested on its nearest pixels in SIMD lanes without
      // branches (most voxels fail, unpredictably); a bilinear value differs from the nearest
      // by less than the pixel's band behind (the 4 pixels must agree within it), so twice
      // the bands is a safe bound. Same float operations as one voxel at a time, so the same
      // results.
      const float zf = static_cast<float>(z), yf = static_cast<float>(y);
      const float row_x = b.base[0] + b.ez[0] * zf + b.ey[0] * yf;
      const float row_y = b.base[1] + b.ez[1] * zf + b.ey[1] * yf;
      const float row_z = b.base[2] + b.ez[2] * zf + b.ey[2] * yf;
      const Float4 xs = Float4{0.f, 1.f, 2.f, 3.f} + static_cast<float>(sx);
      const Float4 X = row_x + b.ex[0] * xs, Y = row_y + b.ex[1] * xs, Z = row_z + b.ex[2] * xs;
      const Float4 inv_z = 1.f / (Z > 1e-6f ? Z : 1e-6f);
      const Float4 pu = f.fx * X * inv_z + f.cx, pv = f.fy * Y * inv_z + f.cy;
      const Int4 inside = (Z >= f.min_d) & (pu > -0.5f) & (pv > -0.5f) & (pu < width_f - 0.5f) & (pv < height_f - 0.5f);
      // Clamped before the conversion (equal to converting, then clamping, inside the image).
      const Int4 pixel_u = __builtin_convertvector(clamp4(pu + 0.5f, 0.f, static_cast<float>(f.width - 1)), Int4);
      const Int4 pixel_v = __builtin_convertvector(clamp4(pv + 0.5f, 0.f, static_cast<float>(f.height - 1)), Int4);
      const Int4 at_pixel = pixel_v * f.width + pixel_u;
      const Float4 nearest = {depth_data[at_pixel[0]], depth_data[at_pixel[1]], depth_data[at_pixel[2]],
                              depth_data[at_pixel[3]]};
      const PixelBand* p[4] = {&pixel_data[at_pixel[0]], &pixel_data[at_pixel[1]], &pixel_data[at_pixel[2]],
                               &pixel_data[at_pixel[3]]};
      const Float4 behind = {p[0]->behind, p[1]->behind, p[2]->behind, p[3]->behind};
      const Float4 diff = nearest - Z;
      Int4 ok = inside & (nearest >= f.min_d) & (nearest <= f.max_d) & (diff >= -2.f * behind);
      if (!f.carving) { // with free space, every voxel in front is updated
        const Float4 front = {p[0]->front, p[1]->front, p[2]->front, p[3]->front};
        ok &= diff <= front + behind;
      }
      const int lanes = laneMask(ok);
      if (!lanes)
        continue;
      const int first = TsdfBlock::linear(sx, y, z);
      __builtin_prefetch(&b.voxels[first], 1);
      __builtin_prefetch(&b.voxels[first + 3], 1);
      for (int k = 0; k < 4; ++k)
        if (lanes & (1 << k)) {
          out.u[count] = pu[k];
          out.v[count] = pv[k];
          out.z[count] = Z[k];
          out.nearest[count] = nearest[k];
          out.pixel[count] = at_pixel[k];
          out.ui[count] = pixel_u[k];
          out.vi[count] = pixel_v[k];
          out.voxel[count] = first + k;
          ++count;
        }
    }
  return count;
}

namespace {
std::atomic<int> max_lanes{16};
} // namespace

} // namespace detail

int TsdfIntegrator::voxelTestLanes() {
  static const int available = detail::subBlockTestAvx512() ? 16 : detail::subBlockTestAvx2() ? 8 : 4;
  return std::min(available, detail::max_lanes.load());
}

void TsdfIntegrator::setMaxVoxelTestLanes(int lanes) { detail::max_lanes.store(lanes); }

namespace detail {

SubBlockTest subBlockTest() {
  switch (TsdfIntegrator::voxelTestLanes()) {
  case 16: return subBlockTestAvx512();
  case 8: return subBlockTestAvx2();
  default: return subBlockTestPortable;
  }
}

} // namespace detail

} // namespace msf
