// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The body of the wide voxel tests (voxel_test_simd.cpp), included once per instruction set
// inside its namespace and target pragmas; V is the set's vector type and operations.
// No include guard: meant to be included more than once.

/// The voxel test of one sub-block, V's lanes a time: V::kRows rows of 4 voxels.
template <class V>
int testSubBlock(const VoxelTestFrame& f, const VoxelTestBlock& b, int sx, int sy, int sz, VoxelCandidates& out,
                 int count) {
  using F = typename V::F;
  using I = typename V::I;
  using M = typename V::M;
  const float width_f = static_cast<float>(f.width), height_f = static_cast<float>(f.height);
  const F xs = V::add(V::xLanes(), V::set1(static_cast<float>(sx)));
  const F ex0 = V::set1(b.ex[0]), ex1 = V::set1(b.ex[1]), ex2 = V::set1(b.ex[2]);
  const F ey0 = V::set1(b.ey[0]), ey1 = V::set1(b.ey[1]), ey2 = V::set1(b.ey[2]);
  const F fx = V::set1(f.fx), fy = V::set1(f.fy), cx = V::set1(f.cx), cy = V::set1(f.cy);
  const F min_d = V::set1(f.min_d), max_d = V::set1(f.max_d), tiny = V::set1(1e-6f), one = V::set1(1.f);
  const F half = V::set1(0.5f), minus_half = V::set1(-0.5f), zero = V::set1(0.f), minus_two = V::set1(-2.f);
  const F u_end = V::set1(width_f - 0.5f), v_end = V::set1(height_f - 0.5f);
  const F u_last = V::set1(static_cast<float>(f.width - 1)), v_last = V::set1(static_cast<float>(f.height - 1));
  const I width_i = V::set1i(f.width);
  const float* behind_base = &f.pixels->behind;
  const float* front_base = &f.pixels->front;
  for (int z = sz; z < sz + 4; ++z) {
    const float zf = static_cast<float>(z);
    // row = base + ez z + ey y, as the portable kernel: (base + ez z) first.
    const F rz0 = V::set1(b.base[0] + b.ez[0] * zf), rz1 = V::set1(b.base[1] + b.ez[1] * zf);
    const F rz2 = V::set1(b.base[2] + b.ez[2] * zf);
    for (int y = sy; y < sy + 4; y += V::kRows) {
      const F ys = V::add(V::yLanes(), V::set1(static_cast<float>(y)));
      const F X = V::add(V::add(rz0, V::mul(ey0, ys)), V::mul(ex0, xs));
      const F Y = V::add(V::add(rz1, V::mul(ey1, ys)), V::mul(ex1, xs));
      const F Z = V::add(V::add(rz2, V::mul(ey2, ys)), V::mul(ex2, xs));
      const F inv_z = V::div(one, V::max(Z, tiny));
      const F pu = V::add(V::mul(V::mul(fx, X), inv_z), cx), pv = V::add(V::mul(V::mul(fy, Y), inv_z), cy);
      const M inside = V::and_(V::and_(V::and_(V::ge(Z, min_d), V::gt(pu, minus_half)), V::gt(pv, minus_half)),
                               V::and_(V::lt(pu, u_end), V::lt(pv, v_end)));
      const I pixel_u = V::cvtt(V::min(V::max(V::add(pu, half), zero), u_last));
      const I pixel_v = V::cvtt(V::min(V::max(V::add(pv, half), zero), v_last));
      const I at_pixel = V::addi(V::mullo(pixel_v, width_i), pixel_u);
      const F nearest = V::gather(f.depth, at_pixel);
      const I at_band = V::times5(at_pixel);
      const F behind = V::gather(behind_base, at_band);
      const F diff = V::sub(nearest, Z);
      M ok = V::and_(V::and_(inside, V::ge(diff, V::mul(minus_two, behind))),
                     V::and_(V::ge(nearest, min_d), V::le(nearest, max_d)));
      if (!f.carving)
        ok = V::and_(ok, V::le(diff, V::add(V::gather(front_base, at_band), behind)));
      // No branch on the outcome (about half the voxels pass, unpredictably): a vector without
      // candidates stores nothing that counts, and prefetches its first row again.
      const unsigned lanes = V::bits(ok);
      const int first = TsdfBlock::linear(sx, y, z);
      for (int r = 0; r < V::kRows; ++r) {
        const int row = (lanes >> (4 * r)) & 15u ? first + TsdfBlock::kSide * r : first;
        __builtin_prefetch(&b.voxels[row], 1);
        __builtin_prefetch(&b.voxels[row + 3], 1);
      }
      const typename V::Compress keep(lanes);
      keep.store(out.u + count, pu);
      keep.store(out.v + count, pv);
      keep.store(out.z + count, Z);
      keep.store(out.nearest + count, nearest);
      keep.store(out.pixel + count, at_pixel);
      keep.store(out.ui + count, pixel_u);
      keep.store(out.vi + count, pixel_v);
      keep.store(out.voxel + count, V::addi(V::set1i(first), V::voxelLanes()));
      count += __builtin_popcount(lanes);
    }
  }
  return count;
}
