// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>
#include <msf/synthetic/moving_object.h>
#include <msf/synthetic/primitive.h>
#include <msf/synthetic/scene.h>

#include <cstdint>
#include <vector>

namespace msf::synthetic {

/// The street at one instant: the scene's static solids with their hierarchy, and its
/// movers placed where they are at that time. A mover is present while its bounds lie in
/// the street's open stretch (it appears and vanishes inside the buildings across the
/// street's ends). A ray tests the hierarchy, then the bounds of all present movers, of
/// groups of a few movers neighbouring along the street, of each mover of a group it enters,
/// and only then their few solids: a long street has dozens of movers, a hierarchy of two
/// levels is built in no time every frame. Holds a reference to the scene, which must outlive it.
class SceneSnapshot {
public:
  SceneSnapshot(const Scene& scene, double time_s);

  const Scene& scene() const { return *scene_; }
  double time() const { return time_s_; }

  /// Nearest surface, static or moving, with t in (tmin, tmax); false for the sky.
  /// hit.primitive is an index for primitive().
  bool intersect(const Ray& ray, float tmin, float tmax, Hit& hit) const;

  /// The solid of a hit: indices below scene().primitives.size() are the static solids,
  /// the next ones the placed movers' solids; null for the road plane (Hit::kGround).
  const Primitive* primitive(int index) const {
    if (index < 0)
      return nullptr;
    const auto i = static_cast<std::size_t>(index);
    return i < static_count_ ? &scene_->primitives[i] : &placed_[i - static_count_];
  }

  /// What the surface of `hit` looks like to the sensors at world point `world`.
  SurfaceResponse shade(const Hit& hit, V3 world, const Footprint& footprint) const {
    const Primitive* solid = primitive(hit.primitive);
    const Material& material = scene_->materials[solid ? solid->material : scene_->ground_material];
    return shadeSurface(material, solid, hit, world, footprint, scene_->layout);
  }

  /// The movers present at this time, in the scene's order.
  const std::vector<const MovingObject*>& movers() const { return present_; }

private:
  struct PlacedMover {
    V3 lo, hi;                       ///< world bounds of its bounding box
    std::int32_t begin = 0, end = 0; ///< its solids in placed_
  };
  const Scene* scene_;
  double time_s_;
  std::size_t static_count_;
  std::vector<Primitive> placed_;
  std::vector<PlacedMover> placed_movers_;
  struct MoverGroup {
    V3 lo, hi;                       ///< bounds of its movers
    std::int32_t begin = 0, end = 0; ///< its movers in placed_movers_
  };
  std::vector<MoverGroup> groups_;
  V3 movers_lo_, movers_hi_; ///< bounds of all present movers
  std::vector<const MovingObject*> present_;
};

} // namespace msf::synthetic
