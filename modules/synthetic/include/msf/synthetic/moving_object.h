// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/geometry.h>
#include <msf/synthetic/moving_box.h>
#include <msf/synthetic/primitive.h>

#include <cstdint>
#include <vector>

namespace msf::synthetic {

/// A rigid object driving straight along the street at constant speed: its solids in its
/// own frame (origin on the road under its centre, x right, y down, +z its front) and its
/// path, heading `yaw` about world y (its front points along (sin yaw, 0, cos yaw)), so
/// that at time t its origin is at start + t speed (sin yaw, 0, cos yaw).
class MovingObject {
public:
  /// `solids` in the object's frame, each with instance id `object`.
  MovingObject(std::uint32_t object, std::vector<Primitive> solids, V3 start, float yaw, float speed_mps);

  std::uint32_t object() const { return object_; }
  const std::vector<Primitive>& solids() const { return solids_; }
  float yaw() const { return frame_yaw_; }
  float speedMps() const { return speed_mps_; }

  /// World position of its origin at `time_s` (seconds since frame 0).
  V3 originAt(double time_s) const;
  /// Its solids placed in the world at `time_s`, appended to `out`.
  void placeAt(double time_s, std::vector<Primitive>& out) const;
  /// World axis-aligned bounds of its oriented bounding box at `time_s`.
  void boundsAt(double time_s, V3& lo, V3& hi) const;
  /// Its oriented bounding box at `time_s` (the box of its solids in its own frame, carried
  /// along); `frame` is left 0.
  MovingBox boxAt(double time_s) const;

private:
  /// Its bounding box as a solid placed at `time_s`.
  Primitive boxSolidAt(double time_s) const;

  std::uint32_t object_;
  std::vector<Primitive> solids_;
  V3 start_;
  float frame_yaw_;
  float speed_mps_;
  V3 box_center_, box_half_; ///< bounding box in its own frame
};

} // namespace msf::synthetic
