// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace msf::synthetic {

enum class Shape : std::uint8_t { Box, Cylinder, Ellipsoid };

/// Where a ray met a surface. Coordinates are in the primitive's local frame so that
/// textures stick to the object.
struct Hit {
  float t = std::numeric_limits<float>::infinity();
  int primitive = -1;  ///< index into Scene::primitives; kGround for the road plane
  int face = 0;        ///< box: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z; cylinder: 0 side, 1 +cap, 2 -cap
  V3 local;            ///< hit point in the primitive's frame (metres from its centre)
  V3 normal;           ///< unit outward normal, world frame
  static constexpr int kGround = -2;
};

/// A solid of the street: a box, a capped cylinder or an ellipsoid, rotated about the
/// vertical axis only (world y, pointing down as in the camera frame), since street
/// objects stand upright. Solids may overlap; the scene is their union.
struct Primitive {
  Shape shape = Shape::Box;
  std::uint8_t axis = 1;      ///< cylinder axis in the local frame: 0 x, 1 y (vertical), 2 z
  std::uint16_t material = 0; ///< index into Scene::materials
  std::uint32_t object = 0;   ///< 0 background; > 0 a foreground instance (car, pole, person)
  V3 center;                  ///< world
  V3 half;                    ///< box half extents; ellipsoid radii; cylinder: radius on the
                              ///< two other axes, half length on `axis`
  float cos_yaw = 1.f, sin_yaw = 0.f;

  void setYaw(float yaw) {
    cos_yaw = std::cos(yaw);
    sin_yaw = std::sin(yaw);
  }
  V3 dirToLocal(V3 d) const { return {cos_yaw * d.x - sin_yaw * d.z, d.y, sin_yaw * d.x + cos_yaw * d.z}; }
  V3 dirToWorld(V3 d) const { return {cos_yaw * d.x + sin_yaw * d.z, d.y, -sin_yaw * d.x + cos_yaw * d.z}; }
  V3 toLocal(V3 p) const { return dirToLocal(p - center); }
  V3 toWorld(V3 p) const { return center + dirToWorld(p); }

  /// This solid, given in an object's own frame, placed in the world with the object's
  /// origin at `origin` and its heading `yaw`; the solid's own yaw adds to the heading.
  Primitive placed(V3 origin, float yaw) const {
    Primitive frame;
    frame.setYaw(yaw);
    Primitive p = *this;
    p.center = origin + frame.dirToWorld(center);
    p.cos_yaw = frame.cos_yaw * cos_yaw - frame.sin_yaw * sin_yaw;
    p.sin_yaw = frame.sin_yaw * cos_yaw + frame.cos_yaw * sin_yaw;
    return p;
  }

  /// World axis-aligned bounds.
  void bounds(V3& lo, V3& hi) const {
    const float ex = std::fabs(cos_yaw) * half.x + std::fabs(sin_yaw) * half.z;
    const float ez = std::fabs(sin_yaw) * half.x + std::fabs(cos_yaw) * half.z;
    lo = {center.x - ex, center.y - half.y, center.z - ez};
    hi = {center.x + ex, center.y + half.y, center.z + ez};
  }

  /// True when world point p is inside the solid by more than `inset` metres (roughly,
  /// for ellipsoids), used to drop hidden faces from the ground-truth mesh.
  bool contains(V3 p, float inset) const {
    const V3 q = toLocal(p);
    switch (shape) {
    case Shape::Box:
      return std::fabs(q.x) < half.x - inset && std::fabs(q.y) < half.y - inset && std::fabs(q.z) < half.z - inset;
    case Shape::Cylinder: {
      const float s = q[axis], a = q[(axis + 1) % 3], b = q[(axis + 2) % 3];
      const float r = half[(axis + 1) % 3] - inset;
      return std::fabs(s) < half[axis] - inset && r > 0.f && a * a + b * b < r * r;
    }
    case Shape::Ellipsoid: {
      const float x = q.x / (half.x - inset), y = q.y / (half.y - inset), z = q.z / (half.z - inset);
      return x * x + y * y + z * z < 1.f;
    }
    }
    return false;
  }

  /// Nearest entry of `ray` into the solid with t in (tmin, hit.t); fills `hit` and returns
  /// true when found. A ray starting inside the solid does not hit it.
  bool intersect(const Ray& ray, float tmin, Hit& hit) const {
    const V3 o = toLocal(ray.origin), d = dirToLocal(ray.dir);
    switch (shape) {
    case Shape::Box:
      return intersectBox(o, d, tmin, hit);
    case Shape::Cylinder:
      return intersectCylinder(o, d, tmin, hit);
    case Shape::Ellipsoid:
      return intersectEllipsoid(o, d, tmin, hit);
    }
    return false;
  }

private:
  bool intersectBox(V3 o, V3 d, float tmin, Hit& hit) const {
    // Slabs without branches; a zero direction component gives infinite slab distances,
    // which select or reject the box correctly.
    const float ix = 1.f / d.x, iy = 1.f / d.y, iz = 1.f / d.z;
    const float ax = (-half.x - o.x) * ix, bx = (half.x - o.x) * ix;
    const float ay = (-half.y - o.y) * iy, by = (half.y - o.y) * iy;
    const float az = (-half.z - o.z) * iz, bz = (half.z - o.z) * iz;
    const float nx = ax < bx ? ax : bx, ny = ay < by ? ay : by, nz = az < bz ? az : bz;
    const float fx = ax < bx ? bx : ax, fy = ay < by ? by : ay, fz = az < bz ? bz : az;
    int k = 0;
    float t0 = nx;
    if (ny > t0) {
      t0 = ny;
      k = 1;
    }
    if (nz > t0) {
      t0 = nz;
      k = 2;
    }
    const float fxy = fx < fy ? fx : fy, t1 = fxy < fz ? fxy : fz;
    if (!(t0 <= t1) || t0 <= tmin || t0 >= hit.t)
      return false;
    hit.t = t0;
    hit.face = 2 * k + (d[k] > 0.f ? 1 : 0); // entering through the negative side when d > 0
    hit.local = o + d * t0;
    float n[3] = {0.f, 0.f, 0.f};
    n[k] = (hit.face & 1) ? -1.f : 1.f;
    hit.normal = dirToWorld({n[0], n[1], n[2]});
    return true;
  }

  bool intersectCylinder(V3 o, V3 d, float tmin, Hit& hit) const {
    const int ia = axis, ib = (axis + 1) % 3, ic = (axis + 2) % 3;
    const float r = half[ib], len = half[ia];
    const float ob = o[ib], oc = o[ic], db = d[ib], dc = d[ic], os = o[ia], ds = d[ia];
    float best = hit.t;
    int face = -1;
    const float A = db * db + dc * dc;
    if (A > 0.f) {
      const float B = ob * db + oc * dc, C = ob * ob + oc * oc - r * r;
      const float disc = B * B - A * C;
      if (disc >= 0.f) {
        const float t = (-B - std::sqrt(disc)) / A;
        if (t > tmin && t < best && std::fabs(os + t * ds) <= len) {
          best = t;
          face = 0;
        }
      }
    }
    if (ds != 0.f) {
      for (int side = 0; side < 2; ++side) {
        const float s = side == 0 ? len : -len;
        const float t = (s - os) / ds;
        // Enter a cap only from outside: moving towards the inside of the slab.
        if ((side == 0) != (ds < 0.f) || t <= tmin || t >= best)
          continue;
        const float pb = ob + t * db, pc = oc + t * dc;
        if (pb * pb + pc * pc <= r * r) {
          best = t;
          face = 1 + side;
        }
      }
    }
    if (face < 0)
      return false;
    hit.t = best;
    hit.face = face;
    hit.local = o + d * best;
    float n[3] = {0.f, 0.f, 0.f};
    if (face == 0) {
      n[ib] = hit.local[ib] / r;
      n[ic] = hit.local[ic] / r;
    } else {
      n[ia] = face == 1 ? 1.f : -1.f;
    }
    hit.normal = dirToWorld({n[0], n[1], n[2]});
    return true;
  }

  bool intersectEllipsoid(V3 o, V3 d, float tmin, Hit& hit) const {
    const V3 inv{1.f / half.x, 1.f / half.y, 1.f / half.z};
    const V3 os{o.x * inv.x, o.y * inv.y, o.z * inv.z}, ds{d.x * inv.x, d.y * inv.y, d.z * inv.z};
    const float A = dot(ds, ds), B = dot(os, ds), C = dot(os, os) - 1.f;
    const float disc = B * B - A * C;
    if (disc < 0.f || C < 0.f)
      return false;
    const float t = (-B - std::sqrt(disc)) / A;
    if (t <= tmin || t >= hit.t)
      return false;
    hit.t = t;
    hit.face = 0;
    hit.local = o + d * t;
    hit.normal = dirToWorld(normalized({hit.local.x * inv.x * inv.x, hit.local.y * inv.y * inv.y,
                                        hit.local.z * inv.z * inv.z}));
    return true;
  }
};

/// A solid of `shape` with half extents (radii) `half`, turned by `yaw` about the vertical.
inline Primitive makeSolid(Shape shape, V3 center, V3 half, std::uint16_t material, float yaw = 0.f,
                           std::uint32_t object = 0) {
  Primitive p;
  p.shape = shape;
  p.center = center;
  p.half = half;
  p.material = material;
  p.object = object;
  p.setYaw(yaw);
  return p;
}

inline Primitive boxSolid(V3 center, V3 half, std::uint16_t material, float yaw = 0.f, std::uint32_t object = 0) {
  return makeSolid(Shape::Box, center, half, material, yaw, object);
}

/// A capped cylinder along local axis `axis` (0 x, 1 y, 2 z) with the given radius and half length.
inline Primitive cylinderSolid(V3 center, int axis, float radius, float half_length, std::uint16_t material,
                               float yaw = 0.f, std::uint32_t object = 0) {
  float h[3] = {radius, radius, radius};
  h[axis] = half_length;
  Primitive p = makeSolid(Shape::Cylinder, center, {h[0], h[1], h[2]}, material, yaw, object);
  p.axis = static_cast<std::uint8_t>(axis);
  return p;
}

inline Primitive ellipsoidSolid(V3 center, V3 radii, std::uint16_t material, std::uint32_t object = 0) {
  return makeSolid(Shape::Ellipsoid, center, radii, material, 0.f, object);
}

} // namespace msf::synthetic
