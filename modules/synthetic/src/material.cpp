// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/material.h>
#include <msf/synthetic/procedural_noise.h>
#include <msf/synthetic/scene.h>

#include <algorithm>
#include <cmath>

namespace msf::synthetic {

namespace {

constexpr float kPi = 3.14159265f;
constexpr float kMinFootprint = 1e-4f;

struct Rgb {
  float r, g, b;
};
inline Rgb operator*(Rgb c, float s) { return {c.r * s, c.g * s, c.b * s}; }
inline Rgb mix(Rgb a, Rgb b, float t) { return {mixf(a.r, b.r, t), mixf(a.g, b.g, t), mixf(a.b, b.b, t)}; }
inline float luminance(Rgb c) { return 0.30f * c.r + 0.59f * c.g + 0.11f * c.b; }
inline Rgb base(const Material& m) { return {m.r, m.g, m.b}; }

/// Texture coordinates on a face: u along it, v up it (vertical faces) or across it (top),
/// in metres, with the sample footprint along each.
struct FaceCoords {
  float u = 0.f, v = 0.f;   ///< v: height above the solid's foot on vertical faces
  float fu = kMinFootprint, fv = kMinFootprint;
  float length = 0.f;       ///< extent of the face along u
  float height = 0.f;       ///< extent along v
  int axis = 0;             ///< 0, 2 vertical faces; 1 top or bottom
  float iso() const { return std::sqrt(fu * fv); }
};

float footAlong(V3 dx, V3 dy, int k) { return std::max({std::fabs(dx[k]), std::fabs(dy[k]), kMinFootprint}); }

FaceCoords boxFace(const Primitive& p, const Hit& hit, const Footprint& fp) {
  const V3 dx = p.dirToLocal(fp.dx), dy = p.dirToLocal(fp.dy);
  FaceCoords f;
  f.axis = hit.face >> 1;
  if (f.axis == 0) {
    f.u = hit.local.z + p.half.z;
    f.v = p.half.y - hit.local.y;
    f.fu = footAlong(dx, dy, 2);
    f.fv = footAlong(dx, dy, 1);
    f.length = 2.f * p.half.z;
    f.height = 2.f * p.half.y;
  } else if (f.axis == 2) {
    f.u = hit.local.x + p.half.x;
    f.v = p.half.y - hit.local.y;
    f.fu = footAlong(dx, dy, 0);
    f.fv = footAlong(dx, dy, 1);
    f.length = 2.f * p.half.x;
    f.height = 2.f * p.half.y;
  } else {
    f.u = hit.local.x;
    f.v = hit.local.z;
    f.fu = footAlong(dx, dy, 0);
    f.fv = footAlong(dx, dy, 2);
  }
  return f;
}

/// Coordinates on a curved surface: arc length around the axis, position along it.
FaceCoords curvedFace(const Primitive& p, const Hit& hit, const Footprint& fp) {
  FaceCoords f;
  const int a = p.shape == Shape::Cylinder ? p.axis : 1;
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const float radius = p.half[b];
  f.u = std::atan2(hit.local[c], hit.local[b]) * radius;
  f.v = hit.local[a];
  const float foot = std::max({norm(fp.dx), norm(fp.dy), kMinFootprint});
  f.fu = f.fv = foot;
  f.length = 2.f * kPi * radius;
  f.height = 2.f * p.half[a];
  return f;
}

SurfaceResponse make(Rgb c, float reflectivity, float glass = 0.f) {
  return {std::clamp(c.r, 0.f, 1.f), std::clamp(c.g, 0.f, 1.f), std::clamp(c.b, 0.f, 1.f),
          std::clamp(reflectivity, 0.f, 1.f), glass};
}

SurfaceResponse road(const Material& m, V3 w, const Footprint& fp, const StreetLayout& layout) {
  const float X = layout.streetOffset(w.x), Z = w.z;
  const float fX = footAlong(fp.dx, fp.dy, 0), fZ = footAlong(fp.dx, fp.dy, 2);
  const float iso = std::sqrt(fX * fZ);
  // Stains and wear at 0.1-1 m survive the footprint of the road at 10-30 m, where a pixel
  // spans decimetres along the street; stone grain shows up close.
  const float n = fbm(X, Z, m.seed, 1.2f, 7, iso, 0.7f);
  const float grain = fbm(X, Z, m.seed + 11u, 0.09f, 3, iso, 0.8f);
  const float patch = valueNoise(X / 7.f, Z / 7.f, m.seed + 23u);
  // Wear streaks along the driving direction (10x longer than wide): they keep contrast
  // across the image rows where the road is seen at a grazing angle.
  constexpr float kStretch = 10.f;
  const float streaks = fbm(X, Z / kStretch, m.seed + 47u, 0.4f, 5, std::sqrt(fX * fZ / kStretch), 0.65f);
  const float a = 1.f + 0.4f * n + 0.45f * grain + 0.12f * patch + 0.3f * streaks;
  // Dashed centre line (3 m dash, 6 m gap) and solid lines between driving and parking lanes.
  const float lane = layout.lane_width_m;
  float paint = intervalCoverage(X, -0.06, 0.06, fX) * pulseCoverage(Z + 1.3, 9.0, 1.0 / 3.0, fZ);
  paint += intervalCoverage(X, lane - 0.06, lane + 0.06, fX) + intervalCoverage(X, -lane - 0.06, -lane + 0.06, fX);
  paint = std::min(paint, 1.f);
  if (paint > 0.f) // worn paint
    paint *= 0.8f + 0.2f * fbm(X, Z, m.seed + 31u, 0.5f, 3, iso);
  const Rgb asphalt = base(m) * a;
  return make(mix(asphalt, {0.72f, 0.72f, 0.70f}, paint), mixf(m.reflectivity * (1.f + 0.3f * n), 0.75f, paint));
}

SurfaceResponse sidewalk(const Material& m, const Primitive& p, const Hit& hit, V3 w, const Footprint& fp,
                         const StreetLayout& layout) {
  const FaceCoords f = boxFace(p, hit, fp);
  if (f.axis != 1) { // the kerb's face
    const float n = fbm(f.u, f.v, m.seed + 5u, 0.4f, 5, f.iso());
    return make(Rgb{0.34f, 0.33f, 0.32f} * (1.f + 0.2f * n), 0.3f);
  }
  const float X = std::fabs(layout.streetOffset(w.x)), Z = w.z;
  const float fX = f.fu, fZ = f.fv, iso = f.iso();
  const float kerb_end = layout.halfRoadWidth() + 0.25f;
  const float lawn_start = layout.halfRoadWidth() + layout.sidewalk_width_m;
  const float fine = fbm(X, Z, m.seed, 0.6f, 6, iso);
  if (X < kerb_end) {
    const float joint = pulseCoverage(Z, 1.0, 0.015, fZ);
    return make(Rgb{0.42f, 0.41f, 0.40f} * ((1.f + 0.15f * fine) * (1.f - 0.5f * joint)), 0.35f);
  }
  if (X < lawn_start) {
    constexpr float kTile = 0.3f;
    const float fade = std::clamp(kTile / (2.f * std::max(fX, fZ)) - 1.f, 0.f, 1.f);
    const float tile = 0.8f + 0.4f * cellRandom(static_cast<std::int32_t>(std::floor(X / kTile)),
                                                static_cast<std::int32_t>(std::floor(Z / kTile)), m.seed);
    const float joint = std::max(pulseCoverage(X, kTile, 0.04, fX), pulseCoverage(Z, kTile, 0.04, fZ));
    const float shade = mixf(1.f, tile, fade) * (1.f + 0.12f * fine) * (1.f - 0.45f * joint);
    return make(base(m) * shade, m.reflectivity);
  }
  const float grass = fbm(X, Z, m.seed + 41u, 0.5f, 7, iso, 0.7f);
  return make(Rgb{0.09f, 0.16f, 0.05f} * (1.f + 0.6f * grass), 0.5f);
}

SurfaceResponse facade(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = boxFace(p, hit, fp);
  if (f.axis == 1) { // roof
    const float n = fbm(f.u, f.v, m.seed + 3u, 1.0f, 5, f.iso());
    return make(Rgb{0.17f, 0.16f, 0.16f} * (1.f + 0.2f * n), 0.2f);
  }
  if (m.type == MaterialType::BlankWall)
    return make(base(m), m.reflectivity); // deliberately no texture at all
  const float iso = f.iso();
  Rgb wall;
  if (m.type == MaterialType::Brick) {
    constexpr float kRow = 0.075f, kBrick = 0.25f, kJoint = 0.012f;
    const auto row = static_cast<std::int32_t>(std::floor(f.v / kRow));
    const float shift = (row & 1) ? 0.5f * kBrick : 0.f;
    const auto col = static_cast<std::int32_t>(std::floor((f.u + shift) / kBrick));
    const float fade = std::clamp(kRow / (2.f * std::max(f.fu, f.fv)) - 1.f, 0.f, 1.f);
    const float brick = mixf(1.f, 0.75f + 0.5f * cellRandom(col, row, m.seed), fade);
    const float mortar = std::max(pulseCoverage(f.v, kRow, kJoint / kRow, f.fv),
                                  pulseCoverage(f.u + shift, kBrick, kJoint / kBrick, f.fu));
    wall = mix(base(m) * (brick * (1.f + 0.1f * fbm(f.u, f.v, m.seed + 7u, 0.8f, 6, iso))), {0.5f, 0.48f, 0.45f},
               mortar * 0.8f);
  } else {
    const float n = fbm(f.u, f.v, m.seed, 1.5f, 7, iso);
    const float streak = valueNoise(f.u / 0.3f, f.v / 3.f, m.seed + 13u);
    wall = base(m) * (1.f + 0.16f * n + 0.05f * streak);
  }
  // Window grid: frames, then glass, never in the parapet or at the corners.
  const float inside = intervalCoverage(f.u, 0.5, f.length - 0.5, f.fu) *
                       intervalCoverage(f.v, 0.3, f.height - 1.0, f.fv);
  if (inside <= 0.f)
    return make(wall, m.reflectivity);
  const double pitch = m.window_pitch_m, storey = m.floor_height_m;
  const double ww = m.window_width_m, wh = m.window_height_m, frame = 0.09;
  const double u = f.u - m.window_phase_m, v = f.v - m.sill_height_m;
  const float glass = inside * pulseCoverage(u, pitch, ww / pitch, f.fu) * pulseCoverage(v, storey, wh / storey, f.fv);
  const float framed = inside * pulseCoverage(u + frame, pitch, (ww + 2 * frame) / pitch, f.fu) *
                       pulseCoverage(v + frame, storey, (wh + 2 * frame) / storey, f.fv);
  Rgb c = mix(wall, {0.75f, 0.74f, 0.72f}, std::max(framed - glass, 0.f));
  if (glass > 0.f) {
    // Glass reflects the sky: brighter towards the top of each pane, with blurred clouds.
    const float in_pane = static_cast<float>(std::fmod(std::fmod(v, storey) + storey, storey) / wh);
    const float reflection = 0.05f * std::clamp(in_pane, 0.f, 1.f) + 0.04f * fbm(f.u, f.v, m.seed + 17u, 2.0f, 3, iso);
    const Rgb pane{0.05f + reflection, 0.065f + reflection, 0.08f + 1.2f * reflection};
    c = mix(c, pane, glass);
  }
  return make(c, mixf(m.reflectivity, 0.05f, glass), glass);
}

SurfaceResponse carBody(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = boxFace(p, hit, fp);
  const Rgb paint = base(m) * (1.f + 0.05f * fbm(f.u, f.v, m.seed, 0.6f, 5, f.iso()));
  const float paint_reflectivity = 0.12f + 0.5f * luminance(base(m));
  if (f.axis == 1)
    return make(paint, paint_reflectivity);
  Rgb c = paint;
  float reflectivity = paint_reflectivity;
  if (f.axis == 0) { // sides: door seams and a rubbing strip
    const float seams = intervalCoverage(f.u, 0.36 * f.length, 0.36 * f.length + 0.012, f.fu) +
                        intervalCoverage(f.u, 0.63 * f.length, 0.63 * f.length + 0.012, f.fu);
    c = c * (1.f - 0.7f * std::min(seams, 1.f));
    c = mix(c, {0.05f, 0.05f, 0.05f}, intervalCoverage(f.v, 0.16, 0.22, f.fv));
  } else { // front (+z) and back (-z): lights, number plate, bumper
    const double W = f.length;
    const bool front = hit.face == 4;
    const float lights = intervalCoverage(f.v, 0.42, 0.56, f.fv) *
                         (intervalCoverage(f.u, 0.08, 0.42, f.fu) + intervalCoverage(f.u, W - 0.42, W - 0.08, f.fu));
    c = mix(c, front ? Rgb{0.85f, 0.85f, 0.8f} : Rgb{0.55f, 0.04f, 0.03f}, lights);
    const float plate = intervalCoverage(f.v, 0.18, 0.29, f.fv) * intervalCoverage(f.u, W / 2 - 0.26, W / 2 + 0.26, f.fu);
    const float text = intervalCoverage(f.v, 0.205, 0.265, f.fv) *
                       intervalCoverage(f.u, W / 2 - 0.22, W / 2 + 0.21, f.fu) *
                       pulseCoverage(f.u - (W / 2 - 0.22), 0.05, 0.55, f.fu);
    c = mix(c, {0.8f, 0.8f, 0.78f}, plate);
    c = mix(c, {0.04f, 0.04f, 0.05f}, text);
    c = mix(c, {0.05f, 0.05f, 0.05f}, intervalCoverage(f.v, 0.0, 0.12, f.fv));
    reflectivity = mixf(reflectivity, 0.95f, plate); // plates are retroreflective
  }
  return make(c, reflectivity);
}

SurfaceResponse carCabin(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = boxFace(p, hit, fp);
  const Rgb paint = base(m);
  if (f.axis == 1)
    return make(paint, 0.12f + 0.5f * luminance(paint));
  float frame = intervalCoverage(f.u, -1.0, 0.08, f.fu) + intervalCoverage(f.u, f.length - 0.08, f.length + 1.0, f.fu) +
                intervalCoverage(f.v, f.height - 0.05, f.height + 1.0, f.fv) + intervalCoverage(f.v, -1.0, 0.04, f.fv);
  if (f.axis == 0)
    frame += intervalCoverage(f.u, f.length / 2 - 0.05, f.length / 2 + 0.05, f.fu);
  const float glass = 1.f - std::min(frame, 1.f);
  const float reflection = 0.06f * (f.v / std::max(f.height, 0.1f)) + 0.05f * fbm(f.u, f.v, m.seed + 3u, 0.8f, 4, f.iso());
  const Rgb pane{0.04f + reflection, 0.05f + reflection, 0.06f + 1.2f * reflection};
  return make(mix(paint, pane, glass), mixf(0.3f, 0.05f, glass), glass);
}

SurfaceResponse tyre(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = curvedFace(p, hit, fp);
  const Rgb rubber{0.035f, 0.035f, 0.035f};
  if (hit.face == 0)
    return make(rubber * (1.f + 0.25f * fbm(f.u, f.v, m.seed, 0.2f, 4, f.fu)), 0.08f);
  const int b = (p.axis + 1) % 3, c = (p.axis + 2) % 3;
  const float rho = std::sqrt(hit.local[b] * hit.local[b] + hit.local[c] * hit.local[c]);
  const float rim = intervalCoverage(rho, 0.0, 0.2, f.fu);
  const float angle = std::atan2(hit.local[c], hit.local[b]);
  const float spokes = pulseCoverage(angle * rho, 2.0 * kPi * rho / 5.0, 0.6, f.fu) *
                       intervalCoverage(rho, 0.05, 0.17, f.fu);
  const Rgb metal = Rgb{0.5f, 0.5f, 0.52f} * (1.f - 0.85f * (1.f - spokes) * intervalCoverage(rho, 0.05, 0.17, f.fu));
  return make(mix(rubber, metal, rim), mixf(0.08f, 0.4f, rim));
}

SurfaceResponse metal(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = p.shape == Shape::Box ? boxFace(p, hit, fp) : curvedFace(p, hit, fp);
  return make(base(m) * (1.f + 0.1f * fbm(f.u, f.v, m.seed, 0.5f, 5, f.iso())), m.reflectivity);
}

SurfaceResponse signPlate(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = boxFace(p, hit, fp);
  if (hit.face != 5)
    return make({0.3f, 0.3f, 0.3f}, 0.3f);
  const float rho = std::sqrt(hit.local.x * hit.local.x + hit.local.y * hit.local.y);
  const float foot = std::max(f.fu, f.fv);
  const float ring = intervalCoverage(rho, 0.22, 0.29, foot), inner = intervalCoverage(rho, 0.0, 0.22, foot);
  Rgb c = mix({0.3f, 0.3f, 0.3f}, base(m), ring);
  c = mix(c, {0.82f, 0.82f, 0.8f}, inner);
  return make(c, mixf(0.3f, 0.9f, ring + inner));
}

SurfaceResponse cloth(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = p.shape == Shape::Box ? boxFace(p, hit, fp) : curvedFace(p, hit, fp);
  return make(base(m) * (1.f + 0.25f * fbm(f.u, f.v, m.seed, 0.35f, 6, f.iso())), m.reflectivity);
}

SurfaceResponse skin(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = curvedFace(p, hit, fp);
  const float hair = intervalCoverage(hit.local.y, -1.0, -0.02, f.fv);
  return make(mix(base(m), {0.06f, 0.045f, 0.035f}, hair), 0.3f);
}

SurfaceResponse bark(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = curvedFace(p, hit, fp);
  const float furrows = fbm(f.u * 6.f, f.v * 0.6f, m.seed, 0.25f, 5, f.fu * 6.f);
  const float n = fbm(f.u, f.v, m.seed + 9u, 0.4f, 4, f.fu);
  return make(base(m) * (1.f + 0.35f * furrows + 0.15f * n), m.reflectivity);
}

SurfaceResponse foliage(const Material& m, const Primitive& p, const Hit& hit, const Footprint& fp) {
  const FaceCoords f = curvedFace(p, hit, fp);
  const float n = fbm(f.u, f.v, m.seed, 1.2f, 8, f.fu, 0.65f);
  const float leaves = std::clamp(0.55f + 0.9f * n, 0.1f, 1.6f);
  return make(base(m) * leaves, m.reflectivity);
}

} // namespace

SurfaceClass surfaceClass(MaterialType type) {
  switch (type) {
  case MaterialType::Road:
  case MaterialType::Sidewalk:
    return SurfaceClass::Ground;
  case MaterialType::Plaster:
  case MaterialType::Brick:
  case MaterialType::BlankWall:
    return SurfaceClass::Building;
  case MaterialType::CarPaint:
  case MaterialType::CarCabin:
  case MaterialType::Tyre:
    return SurfaceClass::Car;
  case MaterialType::Metal:
  case MaterialType::SignPlate:
    return SurfaceClass::Pole;
  case MaterialType::Cloth:
  case MaterialType::Skin:
    return SurfaceClass::Person;
  case MaterialType::Bark:
  case MaterialType::Foliage:
    return SurfaceClass::Tree;
  }
  return SurfaceClass::Building; // not reached: every type is listed above
}

const char* surfaceClassName(SurfaceClass c) {
  static const char* const kNames[] = {"ground", "building", "car", "pole", "person", "tree"};
  static_assert(sizeof kNames / sizeof kNames[0] == static_cast<std::size_t>(SurfaceClass::Count));
  return kNames[static_cast<std::size_t>(c)];
}

SurfaceResponse shadeSurface(const Material& material, const Primitive* primitive, const Hit& hit, V3 world,
                             const Footprint& footprint, const StreetLayout& layout) {
  if (primitive == nullptr || material.type == MaterialType::Road)
    return road(material, world, footprint, layout);
  const Primitive& p = *primitive;
  switch (material.type) {
  case MaterialType::Road:
    break;
  case MaterialType::Sidewalk:
    return sidewalk(material, p, hit, world, footprint, layout);
  case MaterialType::Plaster:
  case MaterialType::Brick:
  case MaterialType::BlankWall:
    return facade(material, p, hit, footprint);
  case MaterialType::CarPaint:
    return carBody(material, p, hit, footprint);
  case MaterialType::CarCabin:
    return carCabin(material, p, hit, footprint);
  case MaterialType::Tyre:
    return tyre(material, p, hit, footprint);
  case MaterialType::Metal:
    return metal(material, p, hit, footprint);
  case MaterialType::SignPlate:
    return signPlate(material, p, hit, footprint);
  case MaterialType::Cloth:
    return cloth(material, p, hit, footprint);
  case MaterialType::Skin:
    return skin(material, p, hit, footprint);
  case MaterialType::Bark:
    return bark(material, p, hit, footprint);
  case MaterialType::Foliage:
    return foliage(material, p, hit, footprint);
  }
  return make(base(material), material.reflectivity);
}

} // namespace msf::synthetic
