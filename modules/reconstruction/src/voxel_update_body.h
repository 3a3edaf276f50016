// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The body of the wide voxel updates (voxel_test_simd.cpp), included once per instruction set
// inside its namespace and target pragmas after the voxel test's, with the same V.
// No include guard: meant to be included more than once.

/// std::min(a, b) and std::max(a, b) as the portable kernel's: the second operand on a tie or NaN.
template <class V>
MSF_SIMD_INLINE typename V::F stdMin(typename V::F a, typename V::F b) { return V::min(b, a); }
template <class V>
MSF_SIMD_INLINE typename V::F stdMax(typename V::F a, typename V::F b) { return V::max(b, a); }
/// std::clamp(x, lo, hi): x < lo ? lo : hi < x ? hi : x.
template <class V>
MSF_SIMD_INLINE typename V::F stdClamp(typename V::F x, typename V::F lo, typename V::F hi) {
  return V::select(V::lt(x, lo), lo, V::select(V::lt(hi, x), hi, x));
}

/// The frame's depth where candidates project to (u, v): the bilinear blend of the 4 pixels
/// around, where all lie in the image, have depth and agree within `behind` (when f.bilinear),
/// else the nearest pixel's. `quad_min` is the least of the 4 (`nearest` outside the image).
template <class V>
MSF_SIMD_INLINE typename V::F sampleDepth(const VoxelUpdateFrame& f, typename V::M valid, typename V::F u,
                                          typename V::F v, typename V::F nearest, typename V::F behind,
                                          typename V::F& quad_min) {
  using F = typename V::F;
  using I = typename V::I;
  using M = typename V::M;
  const F zero = V::set1(0.f), one = V::set1(1.f);
  const I width = V::set1i(f.width), height = V::set1i(f.height), one_i = V::set1i(1);
  const I u0 = V::cvtt(u), v0 = V::cvtt(v);
  const M quad = V::and_(V::and_(valid, V::and_(V::ge(u, zero), V::ge(v, zero))),
                         V::and_(V::lti(V::addi(u0, one_i), width), V::lti(V::addi(v0, one_i), height)));
  const I at = V::addi(V::mullo(v0, width), u0);
  const F d00 = V::gatherm(f.depth, at, quad), d10 = V::gatherm(f.depth + 1, at, quad);
  const F d01 = V::gatherm(f.depth + f.width, at, quad), d11 = V::gatherm(f.depth + f.width + 1, at, quad);
  const F lo = stdMin<V>(stdMin<V>(d00, d10), stdMin<V>(d01, d11));
  const F hi = stdMax<V>(stdMax<V>(d00, d10), stdMax<V>(d01, d11));
  quad_min = V::select(quad, lo, nearest);
  if (!f.bilinear)
    return nearest;
  const M blend = V::and_(quad, V::and_(V::gt(lo, zero), V::lt(V::sub(hi, lo), behind)));
  const F a = V::sub(u, V::cvtf(u0)), b = V::sub(v, V::cvtf(v0));
  const F one_a = V::sub(one, a), one_b = V::sub(one, b);
  const F blended = V::add(V::mul(V::add(V::mul(d00, one_a), V::mul(d10, a)), one_b),
                           V::mul(V::add(V::mul(d01, one_a), V::mul(d11, a)), b));
  return V::select(blend, blended, nearest);
}

/// The voxels' words of r, g, b and flags (`rgbf`) with the `coloured` ones' colours the
/// weighted mean with their pixels' (candidates k..): old_weight theirs, w the pixel's,
/// inv 1 / (old_weight + w).
template <class V>
MSF_SIMD_INLINE typename V::I blendColours(const VoxelUpdateFrame& f, const VoxelCandidates& c, int k,
                                           typename V::I rgbf, typename V::M coloured, typename V::F old_weight,
                                           typename V::F w, typename V::F inv) {
  using F = typename V::F;
  using I = typename V::I;
  using M = typename V::M;
  const F half = V::set1(0.5f);
  const I byte = V::set1i(0xff), zero_i = V::set1i(0), one_i = V::set1i(1);
  // A pixel's 3 bytes as the top of the 4 from the byte before (the low 3 at pixel 0).
  const I offset = V::addi(V::mullo(V::loadi(c.vi + k), V::set1i(f.color_step)), V::times3(V::loadi(c.ui + k)));
  const M first = V::eqi(offset, zero_i);
  const I word = V::gatheri1(f.color, V::selecti(first, offset, V::subi(offset, one_i)), coloured);
  const I bgr = V::srlv(word, V::selecti(first, zero_i, V::set1i(8)));
  I mixed = V::andi(rgbf, V::set1i(static_cast<std::int32_t>(0xff000000u))); // the flags
  for (int ch = 0; ch < 3; ++ch) { // r, g, b: the voxel's bytes 0, 1, 2; the image's 2, 1, 0
    const F mine = V::cvtf(V::andi(V::srli(rgbf, 8 * ch), byte));
    const F seen = V::cvtf(V::andi(V::srli(bgr, 8 * (2 - ch)), byte));
    const I mean = V::cvtt(V::add(V::mul(V::add(V::mul(mine, old_weight), V::mul(seen, w)), inv), half));
    mixed = V::ori(mixed, V::slli(V::andi(mean, byte), 8 * ch));
  }
  return V::selecti(coloured, mixed, rgbf);
}

/// The update of a block's candidates, V's lanes a time: blockUpdatePortable's float operations
/// lane for lane, its branches as masks. A block's candidates are distinct voxels, so the
/// scatters of one vector never collide.
template <class V>
VoxelUpdateResult updateBlock(const VoxelUpdateFrame& f, const VoxelCandidates& c, int count, TsdfVoxel* voxels,
                              std::uint16_t* listed_index, float* listed_sdf) {
  using F = typename V::F;
  using I = typename V::I;
  using M = typename V::M;
  static_assert(sizeof(TsdfVoxel) == 3 * sizeof(float), "the gathers index TsdfVoxel's fields as 4-byte words");
  const float* pixel_base = &f.pixels->scale; // scale, front, behind, weight, free
  float* voxel_sdf = &voxels->sdf;
  float* voxel_weight = &voxels->weight;
  // r, g, b and flags as one word (from the array, not from r: GCC checks a store's object).
  auto* voxel_colour = reinterpret_cast<std::int32_t*>(reinterpret_cast<char*>(voxels) + offsetof(TsdfVoxel, r));
  const F zero = V::set1(0.f), one = V::set1(1.f);
  const F trunc = V::set1(f.trunc), minus_trunc = V::set1(-f.trunc);
  const F vs = V::set1(f.voxel_size), minus_vs = V::set1(-f.voxel_size);
  const F colour_band = V::set1(f.colour_band), max_weight = V::set1(f.max_weight);
  const F smooth_band = V::set1(f.smooth_band), sign = V::set1(-0.f);
  const F pass_sigmas2 = V::set1(f.pass_sigmas2);
  const I max_passes = V::set1i(TsdfVoxel::kMaxPasses);
  const I passes_cleared = V::set1i(~(std::int32_t{TsdfVoxel::kPassesMask} << 24));
  const I reappeared_bit = V::set1i(std::int32_t{TsdfVoxel::kReappeared} << 24);
  const I one_i = V::set1i(1), zero_i = V::set1i(0);
  VoxelUpdateResult out;
  I negative = zero_i;
  unsigned signs_neg = 0, signs_pos = 0;
  for (int k = 0; k < count; k += V::kLanes) {
    const M valid = V::firstLanes(count - k);
    const F u = V::load(c.u + k), v = V::load(c.v + k), z = V::load(c.z + k), nearest = V::load(c.nearest + k);
    const I pixel = V::loadi(c.pixel + k);
    F scale, band, behind, pixel_weight;
    V::records4(pixel_base, pixel, valid, scale, band, behind, pixel_weight);
    const F pixel_free = V::gatherm(pixel_base + 4, V::times5(pixel), valid);
    F quad_min;
    const F d = sampleDepth<V>(f, valid, u, v, nearest, behind, quad_min);
    const F diff = V::sub(d, z);
    const M in_band = V::le(diff, band);
    M keep = V::andnot(valid, V::lt(diff, V::xor_(behind, sign)));
    M kept_band = in_band;
    if (f.carving)
      kept_band = V::or_(in_band, V::and_(V::gt(quad_min, zero), V::gt(V::sub(quad_min, z), band)));
    keep = V::and_(V::and_(keep, kept_band), V::gt(pixel_weight, zero));
    const F sdf = stdClamp<V>(V::mul(V::select(in_band, diff, band), scale), minus_trunc, trunc);
    F w = V::select(in_band, pixel_weight, pixel_free);
    if (f.dropoff) {
      const F reach = V::mul(behind, scale);
      const M drop = V::and_(in_band, V::and_(V::lt(sdf, minus_vs), V::gt(reach, vs)));
      w = V::select(drop, V::mul(w, V::div(V::add(reach, sdf), V::sub(reach, vs))), w);
    }
    keep = V::and_(keep, V::gt(w, zero));
    if (!V::bits(keep))
      continue;

    const I voxel = V::loadi(c.voxel + k);
    const I at_voxel = V::times3(voxel);
    const F old_sdf = V::gatherm(voxel_sdf, at_voxel, keep), old_weight = V::gatherm(voxel_weight, at_voxel, keep);
    const F total = V::add(old_weight, w);
    const F inv = V::div(one, total);
    const F new_sdf = stdClamp<V>(V::mul(V::add(V::mul(old_sdf, old_weight), V::mul(sdf, w)), inv), minus_trunc, trunc);
    I rgbf = V::gatheri4(voxel_colour, at_voxel, keep);
    if (f.color) {
      const M coloured = V::and_(V::and_(keep, in_band), V::lt(V::andnot(sdf, sign), colour_band));
      if (V::bits(coloured))
        rgbf = blendColours<V>(f, c, k, rgbf, coloured, old_weight, w, inv);
    }
    // updateVoxel's passes and reappeared of passedThrough(quad_min - z): the flags are the word's top byte.
    const F ahead = V::sub(quad_min, z);
    const M passed = V::and_(V::gt(ahead, trunc), V::gt(V::mul(V::mul(ahead, ahead), pixel_weight), pass_sigmas2));
    const I passes = V::andi(V::srli(rgbf, 24 + TsdfVoxel::kPassesShift), max_passes);
    const I cleared = V::andi(rgbf, passes_cleared);
    const I counted = V::selecti(V::eqi(passes, max_passes), passes, V::addi(passes, one_i));
    const I reappeared = V::selecti(V::eqi(passes, zero_i), zero_i, reappeared_bit); // seen after a pass
    rgbf = V::selecti(passed, V::ori(cleared, V::slli(counted, 24 + TsdfVoxel::kPassesShift)),
                      V::ori(cleared, reappeared));
    V::scatteri(voxel_colour, at_voxel, keep, rgbf);
    V::scatter(voxel_sdf, at_voxel, keep, new_sdf);
    V::scatter(voxel_weight, at_voxel, keep, V::min(max_weight, total)); // std::min(total, max_weight)

    const M below = V::and_(keep, V::lt(new_sdf, zero));
    signs_neg |= V::bits(below);
    signs_pos |= V::bits(V::andnot(keep, below));
    // TsdfBlock::subBlockOf, bit per lane.
    const I sub = V::ori(V::ori(V::andi(V::srli(voxel, 2), one_i), V::andi(V::srli(voxel, 4), V::set1i(2))),
                         V::andi(V::srli(voxel, 6), V::set1i(4)));
    negative = V::ori(negative, V::selecti(below, V::sllv(one_i, sub), zero_i));
    if (f.regularized) {
      const unsigned near = V::bits(V::and_(keep, V::lt(V::andnot(new_sdf, sign), smooth_band)));
      const typename V::Compress list(near);
      list.store(listed_sdf + out.listed, new_sdf);
      list.store16(listed_index + out.listed, voxel);
      out.listed += __builtin_popcount(near);
    }
    out.updated += __builtin_popcount(V::bits(keep));
  }
  out.signs =
      static_cast<std::uint8_t>((signs_neg ? TsdfBlock::kHasNegative : 0) | (signs_pos ? TsdfBlock::kHasPositive : 0));
  out.negative = static_cast<std::uint8_t>(V::orLanes(negative));
  return out;
}
