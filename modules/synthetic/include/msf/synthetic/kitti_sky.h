// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>

#include <cstdint>

namespace msf::synthetic {

/// Linear RGB radiance of the sky along a ray; above 1 is past the camera's white (it clips).
struct SkyRadiance {
  float r = 0.f, g = 0.f, b = 0.f;
};

/// The sky as KITTI's cameras see it (synthetic.sky kitti): overexposed, a pale blue that clips
/// in the blue channel everywhere and in the grey cameras up to about 12 degrees above the
/// horizon and in soft clouds, a smooth gradient above. A flat clipped patch beside a crown gives
/// SGBM no cost to tell disparities apart, so its paths carry the crown's disparity over it.
/// A function of the direction alone (the sky is at infinity: disparity 0), the clouds fixed in
/// the world and drawn from `seed`. `dir` is in the world (y down) and need not be unit length.
SkyRadiance kittiSky(V3 dir, std::uint32_t seed);

} // namespace msf::synthetic
