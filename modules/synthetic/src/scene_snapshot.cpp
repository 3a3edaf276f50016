// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/scene_snapshot.h>

#include <algorithm>

namespace msf::synthetic {

SceneSnapshot::SceneSnapshot(const Scene& scene, double time_s)
    : scene_(&scene), time_s_(time_s), static_count_(scene.primitives.size()) {
  for (const MovingObject& mover : scene.movers) {
    PlacedMover m;
    mover.boundsAt(time_s, m.lo, m.hi);
    if (m.lo.z < scene.layout.openBeginZ() || m.hi.z > scene.layout.openEndZ())
      continue;
    // Slack for the rounding between the box and its placed solids: rays test it first.
    m.lo = m.lo - V3{1e-3f, 1e-3f, 1e-3f};
    m.hi = m.hi + V3{1e-3f, 1e-3f, 1e-3f};
    m.begin = static_cast<std::int32_t>(placed_.size());
    mover.placeAt(time_s, placed_);
    m.end = static_cast<std::int32_t>(placed_.size());
    movers_lo_ = placed_movers_.empty() ? m.lo : minV(movers_lo_, m.lo);
    movers_hi_ = placed_movers_.empty() ? m.hi : maxV(movers_hi_, m.hi);
    placed_movers_.push_back(m);
    present_.push_back(&mover);
  }
  // Groups of movers neighbouring along the longest axis of their bounds (the street's):
  // a ray meets the movers of a few groups at most.
  constexpr std::size_t kGroup = 4;
  if (placed_movers_.size() > kGroup) {
    const V3 extent = movers_hi_ - movers_lo_;
    const int axis = extent.x > extent.z ? (extent.x > extent.y ? 0 : 1) : (extent.z > extent.y ? 2 : 1);
    std::stable_sort(placed_movers_.begin(), placed_movers_.end(), [axis](const PlacedMover& a, const PlacedMover& b) {
      return a.lo[axis] + a.hi[axis] < b.lo[axis] + b.hi[axis];
    });
  }
  for (std::size_t i = 0; i < placed_movers_.size(); i += kGroup) {
    MoverGroup g;
    g.begin = static_cast<std::int32_t>(i);
    g.end = static_cast<std::int32_t>(std::min(placed_movers_.size(), i + kGroup));
    g.lo = placed_movers_[i].lo;
    g.hi = placed_movers_[i].hi;
    for (std::int32_t k = g.begin; k < g.end; ++k) {
      g.lo = minV(g.lo, placed_movers_[static_cast<std::size_t>(k)].lo);
      g.hi = maxV(g.hi, placed_movers_[static_cast<std::size_t>(k)].hi);
    }
    groups_.push_back(g);
  }
}

bool SceneSnapshot::intersect(const Ray& ray, float tmin, float tmax, Hit& hit) const {
  bool found = scene_->intersect(ray, tmin, tmax, hit);
  if (placed_movers_.empty())
    return found;
  const V3 inv{1.f / ray.dir.x, 1.f / ray.dir.y, 1.f / ray.dir.z};
  float entry = 0.f;
  // The movers are cars on the road, below the sensors: most rays pass over all of them.
  if (!rayEntersBox(movers_lo_, movers_hi_, ray.origin, inv, tmin, hit.t, entry))
    return found;
  for (const MoverGroup& g : groups_) {
    if (groups_.size() > 1 && !rayEntersBox(g.lo, g.hi, ray.origin, inv, tmin, hit.t, entry))
      continue;
    for (std::int32_t k = g.begin; k < g.end; ++k) {
      const PlacedMover& m = placed_movers_[static_cast<std::size_t>(k)];
      if (!rayEntersBox(m.lo, m.hi, ray.origin, inv, tmin, hit.t, entry))
        continue;
      for (std::int32_t i = m.begin; i < m.end; ++i)
        if (placed_[static_cast<std::size_t>(i)].intersect(ray, tmin, hit)) {
          hit.primitive = static_cast<int>(static_count_) + i;
          found = true;
        }
    }
  }
  return found;
}

} // namespace msf::synthetic
