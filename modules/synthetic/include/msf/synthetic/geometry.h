// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cmath>

namespace msf::synthetic {

/// A small float vector for the ray caster's inner loops (single precision is ample for a
/// scene of a few hundred metres and halves the memory traffic).
struct V3 {
  float x = 0.f, y = 0.f, z = 0.f;
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator*(float s, V3 a) { return a * s; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float norm(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 normalized(V3 a) { return a * (1.f / norm(a)); }
inline V3 minV(V3 a, V3 b) { return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)}; }
inline V3 maxV(V3 a, V3 b) { return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)}; }

/// A ray; `dir` need not be unit length, and t is measured in units of it (for a camera
/// ray with dir = (x', y', 1) in camera axes, t is the depth z).
struct Ray {
  V3 origin;
  V3 dir;
};

/// Entry distance of a ray into the axis-aligned box [lo, hi] if it meets it within
/// [tmin, tmax]; `inv` is 1 / the ray's direction, per axis. A NaN from 0 * inf (a ray in a
/// slab's plane) fails both comparisons and keeps the interval.
inline bool rayEntersBox(const V3& lo, const V3& hi, const V3& origin, const V3& inv, float tmin, float tmax,
                         float& entry) {
  float t0 = tmin, t1 = tmax;
  auto slab = [&](float l, float h, float o, float i) {
    const float a = (l - o) * i, b = (h - o) * i;
    const float near = a < b ? a : b, far = a < b ? b : a;
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
  };
  slab(lo.x, hi.x, origin.x, inv.x);
  slab(lo.y, hi.y, origin.y, inv.y);
  slab(lo.z, hi.z, origin.z, inv.z);
  entry = t0;
  return t0 <= t1;
}

} // namespace msf::synthetic
