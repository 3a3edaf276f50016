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

} // namespace msf::synthetic
