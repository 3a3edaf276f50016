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

  /// Nearest static surface with t in (tmin, tmax); false for the sky. Of surfaces at the same
  /// distance, the road plane, else the solid the binary hierarchy meets first (see test()).
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

  /// The hierarchy collapsed to 4 children a node (each binary node's children, an inner one
  /// replaced by its own two while there is room): a ray tests a node's 4 boxes at once in
  /// SIMD lanes, by axis from two cache lines, and goes through about half the levels. Lanes
  /// past `count` are unused.
  struct alignas(64) WideNode {
    float lo_x[4], lo_y[4], lo_z[4], hi_x[4], hi_y[4], hi_z[4];
    std::int32_t child[4] = {}; ///< >= 0: a wide node; < 0: the leaf ~child of leaves_
    std::int32_t count = 0;
  };
  struct Leaf {
    std::int32_t first, count; ///< a range of order_
  };
  std::int32_t collapse(std::int32_t binary);
  /// A candidate solid against the hit so far: the nearer wins; of two at the same distance
  /// (coplanar faces of overlapping solids) the one the binary hierarchy's nearest-first
  /// traversal met first, which was the rule before the 4-wide hierarchy: datasets stay
  /// byte for byte what they were.
  bool test(std::int32_t p, const Ray& ray, float tmin, Hit& hit) const;
  /// True when the binary traversal of `ray` tests solid p before solid q: at the node where
  /// their paths part, it descends first into the child the ray enters first (the left one
  /// on a tie); within a leaf, in order_.
  bool metBefore(std::int32_t p, std::int32_t q, const Ray& ray, float tmin) const;

  static constexpr std::int32_t kMaxLeafSize = 8;
  static constexpr int kStackSize = 256;
  std::vector<Node> nodes_; ///< binary, for building, occupied() and metBefore()
  std::vector<std::int32_t> parent_;   ///< per binary node; -1 for the root
  std::vector<std::int32_t> position_; ///< per solid, its entry in order_
  std::vector<std::int32_t> leaf_;     ///< per solid, its binary leaf
  std::vector<WideNode> wide_;
  std::vector<Leaf> leaves_;
  std::vector<std::int32_t> order_;
};

} // namespace msf::synthetic
