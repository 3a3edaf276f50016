// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/kitti_sky.h>
#include <msf/synthetic/procedural_noise.h>

#include <algorithm>

namespace msf::synthetic {

namespace {

// Radiance at the horizon (haze, white past the clip), at the top of the gradient and of a cloud.
constexpr SkyRadiance kHorizon{1.7f, 1.75f, 1.85f};
constexpr SkyRadiance kZenith{0.55f, 0.75f, 1.25f};
constexpr SkyRadiance kCloud{1.5f, 1.5f, 1.55f};
constexpr float kGradientSine = 0.3f; // the gradient spans elevations up to asin of this (about 17.5 deg)
constexpr float kCloudWavelength = 2.f; // on a layer one unit above the camera: a few clouds per view
constexpr float kSharp = 1e-3f;        // the clouds' footprint for fbm: every octave kept

SkyRadiance mix(const SkyRadiance& a, const SkyRadiance& b, float t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

} // namespace

SkyRadiance kittiSky(V3 dir, std::uint32_t seed) {
  const float length = norm(dir);
  const float up = std::clamp(-dir.y / length, 0.f, 1.f); // the sine of the elevation
  const SkyRadiance gradient = mix(kHorizon, kZenith, std::min(1.f, up / kGradientSine));
  // Clouds on a layer above: the direction's point on it, so they hold still as the camera moves.
  const float height = std::max(up, 0.02f) * length;
  const float density = fbm(dir.x / height, dir.z / height, seed, kCloudWavelength, 3, kSharp);
  const float cloud = std::clamp(2.5f * density - 0.25f, 0.f, 1.f);
  return mix(gradient, kCloud, cloud * cloud * (3.f - 2.f * cloud));
}

} // namespace msf::synthetic
