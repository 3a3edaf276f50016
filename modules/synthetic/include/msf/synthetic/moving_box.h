// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace msf::synthetic {

/// Where a moving object was at one frame: its oriented bounding box in the world of
/// poses/00.txt (camera 0 at frame 0: x right, y down, z forward), metres. One line of
/// gt/moving_objects.txt.
struct MovingBox {
  std::size_t frame = 0;
  std::uint32_t object = 0; ///< instance id; obj_map_0 holds it as (object - 1) % 255 + 1
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  /// Half extents along the object's own axes: x right, y down, z towards its front.
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
  /// Radians about world y; the object's front points along world (sin yaw, 0, cos yaw).
  double yaw = 0.0;

  /// True when world point `p` lies in the box grown by `margin` metres on every side (a
  /// negative margin shrinks it: "inside by more than -margin").
  bool contains(const Eigen::Vector3d& p, double margin = 0.0) const;
};

/// The text of gt/moving_objects.txt: a header of comment lines ('#') naming the columns,
/// then one line per box: frame object center_x center_y center_z half_x half_y half_z yaw.
/// Coordinates are printed so that they read back to the same float.
std::string formatMovingBoxes(const std::vector<MovingBox>& boxes);

/// Reads a file written by formatMovingBoxes (comment and blank lines are skipped). Throws
/// IOError naming the file when it is missing, and the file and line when a line is not
/// two whole numbers and seven finite numbers with half extents >= 0.
std::vector<MovingBox> readMovingBoxes(const std::string& path);

} // namespace msf::synthetic
