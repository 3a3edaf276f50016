// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

/// Procedural texture building blocks. Textures are functions of surface coordinates in
/// metres, so every camera sees the same surface pattern (what stereo needs), and they
/// are band-limited by the footprint of a sample on the surface so that distant texture
/// averages out instead of aliasing.
namespace msf::synthetic {

/// 32-bit integer hash (lowbias32).
inline std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

inline std::uint32_t hashCell(std::int32_t ix, std::int32_t iy, std::uint32_t seed) {
  return hash32(static_cast<std::uint32_t>(ix) * 0x9e3779b1U ^ hash32(static_cast<std::uint32_t>(iy) + seed));
}

/// Uniform in [0, 1) for a lattice cell (a brick, a tile).
inline float cellRandom(std::int32_t ix, std::int32_t iy, std::uint32_t seed) {
  return static_cast<float>(hashCell(ix, iy, seed) >> 8) * (1.0f / 16777216.0f);
}

/// Value noise in [-1, 1], quintic interpolation of lattice values.
inline float valueNoise(float x, float y, std::uint32_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy);
  const float tx = x - fx, ty = y - fy;
  const float sx = tx * tx * tx * (tx * (tx * 6.f - 15.f) + 10.f);
  const float sy = ty * ty * ty * (ty * (ty * 6.f - 15.f) + 10.f);
  // hashCell with the row hash shared by the two cells of a row.
  const std::uint32_t row0 = hash32(static_cast<std::uint32_t>(iy) + seed);
  const std::uint32_t row1 = hash32(static_cast<std::uint32_t>(iy + 1) + seed);
  const auto ux = static_cast<std::uint32_t>(ix) * 0x9e3779b1U, ux1 = ux + 0x9e3779b1U;
  constexpr float kScale = 1.0f / 16777216.0f;
  const float a = static_cast<float>(hash32(ux ^ row0) >> 8) * kScale;
  const float b = static_cast<float>(hash32(ux1 ^ row0) >> 8) * kScale;
  const float c = static_cast<float>(hash32(ux ^ row1) >> 8) * kScale;
  const float d = static_cast<float>(hash32(ux1 ^ row1) >> 8) * kScale;
  const float top = a + (b - a) * sx, bottom = c + (d - c) * sx;
  return 2.f * (top + (bottom - top) * sy) - 1.f;
}

/// Fractal sum of `octaves` value-noise layers, the first of wavelength `wavelength_m`,
/// each next one half as long and `gain` as strong. Layers shorter than twice the
/// `footprint_m` fade out (the average of a fine pattern over a pixel is its mean).
/// Roughly in [-1, 1].
inline float fbm(float x, float y, std::uint32_t seed, float wavelength_m, int octaves, float footprint_m,
                 float gain = 0.55f) {
  float total = 0.f, amplitude = 1.f;
  for (int i = 0; i < octaves; ++i, amplitude *= gain)
    total += amplitude;
  float sum = 0.f, lambda = wavelength_m;
  amplitude = 1.f;
  for (int i = 0; i < octaves; ++i, amplitude *= gain, lambda *= 0.5f) {
    const float keep = std::clamp(lambda / (2.f * footprint_m) - 1.f, 0.f, 1.f);
    if (keep <= 0.f)
      break; // every finer octave is faded out too
    sum += amplitude * keep * valueNoise(x / lambda, y / lambda, seed + 977u * static_cast<std::uint32_t>(i));
  }
  return sum / total;
}

/// Share of [x - w/2, x + w/2] covered by the pulses [k P, k P + duty P) of a periodic
/// train: an exactly box-filtered stripe pattern (mortar joints, lane dashes, windows).
inline float pulseCoverage(double x, double period, double duty, double width) {
  const double on = duty * period;
  auto integral = [&](double s) {
    const double k = std::floor(s / period);
    return k * on + std::min(s - k * period, on);
  };
  if (width < 1e-6) {
    const double k = std::floor(x / period);
    return (x - k * period) < on ? 1.f : 0.f;
  }
  return static_cast<float>((integral(x + 0.5 * width) - integral(x - 0.5 * width)) / width);
}

/// Box-filtered indicator of the interval [lo, hi] (a single stripe).
inline float intervalCoverage(double x, double lo, double hi, double width) {
  const double w = std::max(width, 1e-6);
  const double a = std::max(x - 0.5 * w, lo), b = std::min(x + 0.5 * w, hi);
  return b > a ? static_cast<float>((b - a) / w) : 0.f;
}

inline float mixf(float a, float b, float t) { return a + (b - a) * t; }

} // namespace msf::synthetic
