// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/moving_object.h>

#include <utility>

namespace msf::synthetic {

namespace {
/// The rotation of heading `yaw`, as Primitive::placed applies it.
Primitive heading(float yaw) {
  Primitive frame;
  frame.setYaw(yaw);
  return frame;
}
} // namespace

MovingObject::MovingObject(std::uint32_t object, std::vector<Primitive> solids, V3 start, float yaw, float speed_mps)
    : object_(object), solids_(std::move(solids)), start_(start), frame_yaw_(yaw), speed_mps_(speed_mps) {
  V3 lo{0.f, 0.f, 0.f}, hi{0.f, 0.f, 0.f};
  for (std::size_t i = 0; i < solids_.size(); ++i) {
    V3 solid_lo, solid_hi;
    solids_[i].bounds(solid_lo, solid_hi);
    lo = i == 0 ? solid_lo : minV(lo, solid_lo);
    hi = i == 0 ? solid_hi : maxV(hi, solid_hi);
  }
  box_center_ = (lo + hi) * 0.5f;
  box_half_ = (hi - lo) * 0.5f;
}

V3 MovingObject::originAt(double time_s) const {
  // Double precision along the path: a float time times speed drifts over a long drive.
  const V3 forward = heading(frame_yaw_).dirToWorld({0.f, 0.f, 1.f});
  const double travelled = time_s * speed_mps_;
  return {static_cast<float>(start_.x + forward.x * travelled), static_cast<float>(start_.y + forward.y * travelled),
          static_cast<float>(start_.z + forward.z * travelled)};
}

void MovingObject::placeAt(double time_s, std::vector<Primitive>& out) const {
  const V3 origin = originAt(time_s);
  for (const Primitive& solid : solids_)
    out.push_back(solid.placed(origin, frame_yaw_));
}

Primitive MovingObject::boxSolidAt(double time_s) const {
  const V3 center = originAt(time_s) + heading(frame_yaw_).dirToWorld(box_center_);
  return boxSolid(center, box_half_, 0, frame_yaw_, object_);
}

void MovingObject::boundsAt(double time_s, V3& lo, V3& hi) const { boxSolidAt(time_s).bounds(lo, hi); }

MovingBox MovingObject::boxAt(double time_s) const {
  const Primitive solid = boxSolidAt(time_s);
  MovingBox box;
  box.object = object_;
  box.center = {solid.center.x, solid.center.y, solid.center.z};
  box.half_extents = {box_half_.x, box_half_.y, box_half_.z};
  box.yaw = frame_yaw_;
  return box;
}

} // namespace msf::synthetic
