// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>
#include <msf/synthetic/material.h>
#include <msf/synthetic/moving_object.h>
#include <msf/synthetic/primitive.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msf::synthetic {

/// Cross-section of the street in world coordinates (the rectified frame of camera 0 at
/// frame 0: x right, y down, z forward). The street runs along z.
struct StreetLayout {
  float ground_y = 1.65f;         ///< road plane; KITTI's camera 0 is 1.65 m above it
  float road_center_x = -1.625f;  ///< road axis; the car keeps to the right-hand lane
  float lane_width_m = 3.25f;     ///< each of the two driving lanes
  float parking_width_m = 2.25f;  ///< a parking lane on each side
  float kerb_height_m = 0.12f;
  float sidewalk_width_m = 4.5f;  ///< paving from the kerb to the lawn line
  float z_begin = 0.f, z_end = 0.f;
  float cross_gap_m = 5.f;        ///< open road between z_begin, z_end and the buildings across the street

  float halfRoadWidth() const { return lane_width_m + parking_width_m; }
  float sidewalkY() const { return ground_y - kerb_height_m; }
  /// Distance of world x from the road axis, and which side (+1 right, -1 left).
  float streetOffset(float x) const { return x - road_center_x; }
  /// Centre x of the right-hand driving lane (the cameras' lane, driving +z) and of the left one.
  float rightLaneX() const { return road_center_x + 0.5f * lane_width_m; }
  float leftLaneX() const { return road_center_x - 0.5f * lane_width_m; }
  /// The street's open stretch along z, between the buildings across its ends.
  float openBeginZ() const { return z_begin - cross_gap_m; }
  float openEndZ() const { return z_end + cross_gap_m; }
};

/// The street as a union of solids over an infinite road plane, with a bounding volume
/// hierarchy for the ray caster (binned surface area heuristic). Rays that meet
/// nothing see the sky, which returns nothing. The solids and their hierarchy are the
/// static world; `movers` drive through it and are placed at a time by SceneSnapshot.
class Scene {
public:
  StreetLayout layout;
  std::uint16_t ground_material = 0;
  std::vector<Material> materials;
  std::vector<Primitive> primitives;
  /// Foreground objects that move (their materials are in `materials`, their ids follow the
  /// static objects' ids); not in the hierarchy, not in intersect() or occupied().
  std::vector<MovingObject> movers;

  std::uint16_t addMaterial(const Material& material);
  void add(const Primitive& primitive) { primitives.push_back(primitive); }

  /// Builds the hierarchy; call after the last primitive is added.
  void buildIndex();

  /// Nearest static surface with t in (tmin, tmax); false for the sky.
  bool intersect(const Ray& ray, float tmin, float tmax, Hit& hit) const;

  /// True when p lies inside a static solid other than primitives[skip], or below the road
  /// plane, by more than `inset`.
  bool occupied(V3 p, float inset, std::int32_t skip = -1) const;

  /// Number of foreground instances, static and moving (largest object id).
  std::uint32_t objectCount() const;

private:
  struct Node {
    V3 lo, hi;
    std::int32_t index = 0;  ///< leaf: first entry of order_; inner: right child (left is next)
    std::uint16_t count = 0; ///< > 0 for a leaf
    std::uint16_t axis = 0;  ///< split axis of an inner node
  };
  std::int32_t build(std::int32_t begin, std::int32_t end, const std::vector<V3>& lo, const std::vector<V3>& hi,
                     const std::vector<V3>& centroid);

  /// The boxes of an inner node's two children, by axis, so that a ray tests both at once in
  /// 4 SIMD lanes (left lo, right lo, left hi, right hi), from one cache line: the right
  /// child's node is elsewhere in nodes_, and on a long street the hierarchy is not in cache.
  struct alignas(64) ChildBoxes {
    float x[4], y[4], z[4];
  };
  /// Where the ray enters each of an inner node's two children within [tmin, tmax], if it does.
  static void enterChildren(const ChildBoxes& c, const Ray& ray, const V3& inv, float tmin, float tmax, float entry[2],
                            bool enters[2]);

  static constexpr std::int32_t kMaxLeafSize = 8;
  std::vector<Node> nodes_;
  std::vector<ChildBoxes> children_; ///< per node; unused for leaves
  std::vector<std::int32_t> order_;
};

} // namespace msf::synthetic
