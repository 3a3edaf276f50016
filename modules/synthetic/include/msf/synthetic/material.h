// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>
#include <msf/synthetic/primitive.h>

#include <cstdint>

namespace msf::synthetic {

struct StreetLayout;

enum class MaterialType : std::uint8_t {
  Road,      ///< asphalt with lane markings (street coordinates)
  Sidewalk,  ///< kerbstones, paving tiles, lawn behind the building line
  Plaster,   ///< rendered façade with windows
  Brick,     ///< brick façade with windows
  BlankWall, ///< uniformly painted, no windows: stereo cannot match here, LiDAR must carry
  CarPaint,  ///< car body: paint, seams, lights, number plate
  CarCabin,  ///< car greenhouse: glass with pillars, painted roof
  Tyre,      ///< rubber with a metal rim on the caps
  Metal,     ///< poles, lamp heads
  SignPlate, ///< a round traffic sign on its front face
  Cloth,     ///< people's clothes
  Skin,      ///< heads (with hair on top)
  Bark,      ///< tree trunks
  Foliage,   ///< tree crowns
};

/// Appearance of a surface; the pattern is procedural, keyed by `seed`.
struct Material {
  MaterialType type = MaterialType::Plaster;
  float r = 0.5f, g = 0.5f, b = 0.5f; ///< base albedo (linear)
  std::uint32_t seed = 0;
  float reflectivity = 0.3f;          ///< LiDAR infrared reflectivity of the base surface
  // Façade window grid (Plaster, Brick), metres along the wall and above its foot.
  float floor_height_m = 3.2f;
  float window_width_m = 1.2f;
  float window_height_m = 1.5f;
  float window_pitch_m = 3.0f;
  float window_phase_m = 0.f;
  float sill_height_m = 0.9f;
};

/// The kinds of surface the mesh evaluation reports apart (MeshAccuracy::by_class), by material:
/// ground (road, sidewalk), building, car, pole (poles, lamp heads, signs), person, tree.
enum class SurfaceClass : std::uint8_t { Ground, Building, Car, Pole, Person, Tree, Count };
SurfaceClass surfaceClass(MaterialType type);
/// "ground", "building", ...: gt/scene_classes.txt's names.
const char* surfaceClassName(SurfaceClass c);

/// What a surface point looks like to the sensors.
struct SurfaceResponse {
  float r = 0.f, g = 0.f, b = 0.f; ///< albedo (linear)
  float reflectivity = 0.f;        ///< LiDAR
  float glass = 0.f;               ///< share of glass under the sample (LiDAR returns get lost)
};

/// Footprint of one sample on the surface: the change of the hit point (world) for a step
/// of one sample to the right (dx) and one down (dy) in the image. Zero for LiDAR.
struct Footprint {
  V3 dx, dy;
};

/// Appearance of the surface hit by a ray. `primitive` is null for the road plane; `world`
/// is the hit point.
SurfaceResponse shadeSurface(const Material& material, const Primitive* primitive, const Hit& hit, V3 world,
                             const Footprint& footprint, const StreetLayout& layout);

} // namespace msf::synthetic
