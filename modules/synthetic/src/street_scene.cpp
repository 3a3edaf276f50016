// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/car.h>
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/kitti_rig.h>
#include <msf/synthetic/street_scene.h>
#include <msf/synthetic/traffic.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace msf::synthetic {

namespace {

constexpr float kPiF = 3.14159265f;
constexpr float kPlateauOuterX = 48.f; // street offset where the back row of buildings ends
// synthetic.sky kitti: lower buildings and wide, low-hanging crowns. SGBM smears a crown's disparity over
// the clipped sky beside it, and the LiDAR's top ring returning the crown bounds sky carving there.
constexpr float kKittiBuildingScale = 0.6f; // the buildings' height, of the default street's
constexpr float kKittiTrunkDropM = 1.2f;    // the crown starts this much lower
constexpr float kKittiCrownGrowM = 1.0f;    // and its radii are this much larger

struct Rgb3 {
  float r, g, b;
};

/// Builds one street; holds the random stream and the running object id.
class StreetBuilder {
public:
  StreetBuilder(const SyntheticConfig& config, double path_end_z)
      : config_(config), rng_(hashKey(static_cast<std::uint64_t>(config.seed), 0x57ee7ULL)) {
    StreetLayout& L = scene_.layout;
    L.ground_y = static_cast<float>(kCameraHeightM);
    // Beyond the LiDAR's reach behind the start and ahead of the end.
    L.z_begin = -90.f;
    L.z_end = static_cast<float>(path_end_z) + 150.f;
  }

  Scene build() {
    Material road;
    road.type = MaterialType::Road;
    road.r = road.g = 0.16f;
    road.b = 0.17f;
    road.seed = rng_.seed32();
    road.reflectivity = 0.3f;
    scene_.ground_material = scene_.addMaterial(road);
    for (int side : {-1, 1}) {
      addPlateau(side);
      addBuildings(side);
      addBackRow(side);
      addPoles(side);
      addTrees(side);
      addParkedCars(side);
      addPedestrians(side);
    }
    addCrossBuildings();
    scene_.buildIndex();
    return std::move(scene_);
  }

private:
  const StreetLayout& layout() const { return scene_.layout; }
  float worldX(int side, float offset) const { return layout().road_center_x + static_cast<float>(side) * offset; }
  /// World y of a point `height` metres above the road (y points down).
  float yAbove(float height) const { return layout().ground_y - height; }
  float yAboveSidewalk(float height) const { return layout().sidewalkY() - height; }
  float uniform(double lo, double hi) { return static_cast<float>(rng_.uniform(lo, hi)); }
  /// A building's height: with synthetic.sky kitti lower, so that the sky over the street is wide
  /// and the crowns stand against it, as on KITTI's drives.
  float lower(float height) const { return config_.sky == "kitti" ? kKittiBuildingScale * height : height; }

  std::uint16_t material(MaterialType type, Rgb3 c, float reflectivity) {
    Material m;
    m.type = type;
    m.r = c.r;
    m.g = c.g;
    m.b = c.b;
    m.seed = rng_.seed32();
    m.reflectivity = reflectivity;
    return scene_.addMaterial(m);
  }

  /// Raised sidewalk and lawn from the kerb to the back row, in 20 m slabs (tight bounds
  /// for the hierarchy); it reaches below the road so only its top and kerb face show.
  void addPlateau(int side) {
    Material m;
    m.type = MaterialType::Sidewalk;
    m.r = 0.34f;
    m.g = 0.31f;
    m.b = 0.29f;
    m.seed = rng_.seed32();
    m.reflectivity = 0.3f;
    const std::uint16_t mat = scene_.addMaterial(m);
    const float x0 = layout().halfRoadWidth(), x1 = kPlateauOuterX;
    const float top = layout().sidewalkY(), bottom = layout().ground_y + 0.3f;
    for (float z = layout().z_begin - 40.f; z < layout().z_end + 40.f; z += 20.f)
      scene_.add(boxSolid({worldX(side, 0.5f * (x0 + x1)), 0.5f * (top + bottom), z + 10.f},
                          {0.5f * (x1 - x0), 0.5f * (bottom - top), 10.f}, mat));
  }

  std::uint16_t facadeMaterial(bool blank) {
    static const Rgb3 kPlaster[] = {{0.55f, 0.50f, 0.42f}, {0.60f, 0.60f, 0.58f}, {0.58f, 0.52f, 0.32f},
                                    {0.50f, 0.38f, 0.33f}, {0.45f, 0.47f, 0.50f}, {0.62f, 0.60f, 0.55f}};
    static const Rgb3 kBrick[] = {{0.36f, 0.16f, 0.10f}, {0.42f, 0.25f, 0.16f}, {0.30f, 0.22f, 0.18f}};
    static const Rgb3 kBlank[] = {{0.70f, 0.70f, 0.68f}, {0.62f, 0.62f, 0.64f}, {0.66f, 0.60f, 0.50f}};
    Material m;
    const float k = uniform(0.85, 1.1);
    Rgb3 c;
    if (blank) {
      m.type = MaterialType::BlankWall;
      c = kBlank[rng_.index(3)];
    } else if (rng_.chance(0.35)) {
      m.type = MaterialType::Brick;
      c = kBrick[rng_.index(3)];
    } else {
      m.type = MaterialType::Plaster;
      c = kPlaster[rng_.index(6)];
    }
    m.r = c.r * k;
    m.g = c.g * k;
    m.b = c.b * k;
    m.seed = rng_.seed32();
    m.reflectivity = 0.25f + 0.3f * (0.3f * m.r + 0.59f * m.g + 0.11f * m.b);
    m.floor_height_m = uniform(3.0, 3.6);
    m.window_width_m = uniform(0.9, 1.6);
    m.window_height_m = uniform(1.3, 1.8);
    m.window_pitch_m = m.window_width_m + uniform(0.9, 2.2);
    m.window_phase_m = uniform(0.0, m.window_pitch_m);
    m.sill_height_m = uniform(0.8, 1.0);
    return scene_.addMaterial(m);
  }

  /// A building with its front at street offset `front`, `depth` deep, over [z0, z1].
  void addBuilding(int side, float front, float depth, float z0, float z1, float height, bool blank) {
    const std::uint16_t mat = facadeMaterial(blank);
    scene_.add(boxSolid({worldX(side, front + 0.5f * depth), yAboveSidewalk(0.5f * height), 0.5f * (z0 + z1)},
                        {0.5f * depth, 0.5f * height, 0.5f * (z1 - z0)}, mat));
  }

  void addBuildings(int side) {
    const float building_line = layout().halfRoadWidth() + layout().sidewalk_width_m;
    float z = layout().z_begin - 15.f;
    while (z < layout().z_end + 15.f) {
      const float lot = uniform(9.0, 24.0);
      const double roll = rng_.uniform();
      const double blank_share = config_.textureless_share;
      if (roll < blank_share) {
        // Warehouse with blank walls, or a blank garden wall in front of a back building.
        if (rng_.chance(0.5)) {
          addBuilding(side, building_line + uniform(0.0, 1.0), uniform(10.0, 16.0), z, z + lot,
                      lower(uniform(4.0, 9.0)), true);
        } else {
          addBuilding(side, building_line + 0.2f, 0.25f, z, z + lot - 2.5f, uniform(1.8, 2.6), true);
          addBuilding(side, uniform(26.0, 30.0), uniform(8.0, 12.0), z, z + lot, lower(uniform(8.0, 16.0)), false);
        }
      } else if (roll < blank_share + 0.15 * (1.0 - blank_share)) {
        addBuilding(side, uniform(26.0, 30.0), uniform(8.0, 12.0), z, z + lot, lower(uniform(8.0, 16.0)), false);
      } else {
        const float setback = rng_.chance(0.6) ? 0.f : uniform(0.5, 3.0);
        const int floors = 2 + rng_.index(5);
        addBuilding(side, building_line + setback, uniform(10.0, 16.0), z, z + lot,
                    lower(static_cast<float>(floors) * uniform(3.0, 3.5) + 1.f), false);
      }
      z += lot + (rng_.chance(0.5) ? 0.f : uniform(1.0, 4.0));
    }
  }

  /// A closed row at the back, so gaps between buildings do not show the sky at ground level.
  void addBackRow(int side) {
    for (float z = layout().z_begin - 15.f; z < layout().z_end + 15.f;) {
      const float lot = uniform(15.0, 30.0);
      addBuilding(side, kPlateauOuterX - 6.f, 6.f, z, z + lot, lower(uniform(12.0, 24.0)), false);
      z += lot;
    }
  }

  /// Buildings across the street at both ends, so nothing is open to the horizon.
  void addCrossBuildings() {
    for (const float z : {layout().openBeginZ() - 20.f, layout().openEndZ()}) {
      const std::uint16_t mat = facadeMaterial(false);
      const float height = uniform(14.0, 20.0);
      scene_.add(boxSolid({layout().road_center_x, yAbove(0.5f * height), z + 10.f},
                          {kPlateauOuterX + 2.f, 0.5f * height, 10.f}, mat));
    }
  }

  void addPoles(int side) {
    const std::uint16_t metal = material(MaterialType::Metal, {0.33f, 0.34f, 0.35f}, 0.45f);
    const float kerb = layout().halfRoadWidth();
    for (float z = layout().z_begin + uniform(0.0, 20.0); z < layout().z_end; z += uniform(22.0, 32.0)) {
      const std::uint32_t id = ++objects_;
      const float x = worldX(side, kerb + 0.45f), height = uniform(6.5, 8.0);
      scene_.add(cylinderSolid({x, yAboveSidewalk(0.5f * height), z}, 1, 0.07f, 0.5f * height, metal, 0.f, id));
      scene_.add(cylinderSolid({worldX(side, kerb + 0.45f - 0.8f), yAboveSidewalk(height - 0.1f), z}, 0, 0.04f, 0.8f,
                               metal, 0.f, id));
      scene_.add(boxSolid({worldX(side, kerb + 0.45f - 1.55f), yAboveSidewalk(height - 0.2f), z}, {0.28f, 0.07f, 0.13f},
                          metal, 0.f, id));
      poles_z_[side > 0].push_back(z);
      if (rng_.chance(0.45)) { // a traffic sign half-way to the next lamp
        const float zs = z + uniform(8.0, 14.0);
        static const Rgb3 kSign[] = {{0.55f, 0.04f, 0.04f}, {0.04f, 0.12f, 0.5f}};
        const std::uint16_t plate = material(MaterialType::SignPlate, kSign[rng_.index(2)], 0.9f);
        const std::uint32_t sign = ++objects_;
        const float xs = worldX(side, kerb + 0.35f);
        scene_.add(cylinderSolid({xs, yAboveSidewalk(1.3f), zs}, 1, 0.035f, 1.3f, metal, 0.f, sign));
        scene_.add(boxSolid({xs, yAboveSidewalk(2.25f), zs - 0.05f}, {0.3f, 0.3f, 0.015f}, plate, 0.f, sign));
        poles_z_[side > 0].push_back(zs);
      }
    }
  }

  bool nearPole(int side, float z, float distance) const {
    for (const float p : poles_z_[side > 0])
      if (std::fabs(p - z) < distance)
        return true;
    return false;
  }

  void addTrees(int side) {
    const std::uint16_t bark = material(MaterialType::Bark, {0.22f, 0.18f, 0.14f}, 0.4f);
    const float x = worldX(side, layout().halfRoadWidth() + 2.0f);
    for (float z = layout().z_begin + uniform(0.0, 10.0); z < layout().z_end; z += uniform(11.0, 18.0)) {
      if (!rng_.chance(0.55) || nearPole(side, z, 2.5f))
        continue;
      const std::uint16_t leaves =
          material(MaterialType::Foliage, {uniform(0.07, 0.12), uniform(0.15, 0.22), uniform(0.04, 0.07)}, 0.45f);
      float trunk = uniform(2.6, 3.4), rh = uniform(1.7, 2.6), rv = uniform(2.0, 3.0);
      if (config_.sky == "kitti") { // wide crowns from the LiDAR's top ring to above the eaves, as KITTI's
        trunk -= kKittiTrunkDropM;
        rh += kKittiCrownGrowM;
        rv += kKittiCrownGrowM;
      }
      scene_.add(cylinderSolid({x, yAboveSidewalk(0.5f * trunk + 0.25f), z}, 1, uniform(0.12, 0.2),
                               0.5f * trunk + 0.25f, bark));
      scene_.add(ellipsoidSolid({x, yAboveSidewalk(trunk + 0.75f * rv), z}, {rh, rv, rh}, leaves));
      trees_z_[side > 0].push_back(z);
    }
  }

  void addParkedCars(int side) {
    const std::uint16_t rubber = material(MaterialType::Tyre, {0.035f, 0.035f, 0.035f}, 0.08f);
    const float lane_center = layout().halfRoadWidth() - 0.5f * layout().parking_width_m;
    float z = layout().z_begin + 5.f;
    while (z < layout().z_end - 5.f) {
      if (!rng_.chance(config_.parked_car_share)) {
        z += uniform(4.0, 9.0);
        continue;
      }
      const CarLook car = drawCarLook(rng_, scene_);
      // Cars face the way their lane drives: +z on the right, -z on the left.
      const float yaw = uniform(-0.03, 0.03) + (side > 0 ? 0.f : kPiF);
      const V3 base{worldX(side, lane_center + uniform(-0.12, 0.12)), layout().ground_y, z + 0.5f * car.length_m};
      const std::uint32_t id = ++objects_;
      for (const Primitive& solid : carSolids(car, rubber, id))
        scene_.add(solid.placed(base, yaw));
      z += car.length_m + uniform(0.7, 2.0);
    }
  }

  void addPedestrians(int side) {
    static const Rgb3 kClothes[] = {{0.05f, 0.06f, 0.12f}, {0.04f, 0.04f, 0.04f}, {0.3f, 0.3f, 0.3f},
                                    {0.45f, 0.38f, 0.25f}, {0.5f, 0.08f, 0.06f}, {0.1f, 0.25f, 0.12f},
                                    {0.6f, 0.6f, 0.58f}, {0.15f, 0.2f, 0.4f}};
    static const Rgb3 kSkin[] = {{0.70f, 0.52f, 0.42f}, {0.50f, 0.35f, 0.25f}, {0.28f, 0.18f, 0.12f}};
    const float kerb = layout().halfRoadWidth();
    const int count = static_cast<int>((layout().z_end - layout().z_begin) / 30.f);
    for (int i = 0; i < count; ++i) {
      const float z = uniform(layout().z_begin, layout().z_end);
      const float offset = uniform(kerb + 1.0, kerb + layout().sidewalk_width_m - 0.4);
      bool blocked = nearPole(side, z, 1.0f);
      for (const float t : trees_z_[side > 0])
        blocked = blocked || std::fabs(t - z) < 1.0f;
      if (blocked)
        continue;
      const float k = uniform(0.92, 1.08), x = worldX(side, offset);
      const std::uint32_t id = ++objects_;
      const std::uint16_t legs = material(MaterialType::Cloth, kClothes[rng_.index(8)], 0.3f);
      const std::uint16_t top = material(MaterialType::Cloth, kClothes[rng_.index(8)], 0.3f);
      const std::uint16_t head = material(MaterialType::Skin, kSkin[rng_.index(3)], 0.3f);
      scene_.add(cylinderSolid({x, yAboveSidewalk(0.43f * k), z}, 1, 0.13f, 0.43f * k, legs, 0.f, id));
      scene_.add(cylinderSolid({x, yAboveSidewalk(1.18f * k), z}, 1, 0.19f, 0.32f * k, top, 0.f, id));
      scene_.add(ellipsoidSolid({x, yAboveSidewalk(1.62f * k), z}, {0.095f * k, 0.12f * k, 0.1f * k}, head, id));
    }
  }

  const SyntheticConfig& config_;
  SequentialRng rng_;
  Scene scene_;
  std::uint32_t objects_ = 0;
  std::vector<float> poles_z_[2], trees_z_[2];
};

} // namespace

Scene buildStreetScene(const SyntheticConfig& config, double path_end_z) {
  Scene scene = StreetBuilder(config, path_end_z).build();
  addTraffic(config, scene);
  return scene;
}

} // namespace msf::synthetic
