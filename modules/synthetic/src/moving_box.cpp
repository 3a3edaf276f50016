// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/text_records.h>
#include <msf/synthetic/moving_box.h>

#include <cmath>
#include <cstdio>

namespace msf::synthetic {

bool MovingBox::contains(const Eigen::Vector3d& p, double margin) const {
  // Into the box's own axes: the inverse of the yaw rotation about y.
  const Eigen::Vector3d d = p - center;
  const double c = std::cos(yaw), s = std::sin(yaw);
  const Eigen::Vector3d local(c * d.x() - s * d.z(), d.y(), s * d.x() + c * d.z());
  return (local.cwiseAbs() - half_extents).maxCoeff() <= margin;
}

namespace {

const char* kHeader =
    "# Moving objects of a synthetic sequence (msf_synth): one line per frame and moving object present at it.\n"
    "# Each line is the object's oriented bounding box in the world of poses/00.txt (camera 0 at frame 0:\n"
    "# x right, y down, z forward), metres:\n"
    "#   frame object center_x center_y center_z half_x half_y half_z yaw\n"
    "# frame: index into the sequence; object: instance id (obj_map_0 holds (object - 1) % 255 + 1);\n"
    "# half_*: half extents along the object's own axes (x right, y down, z towards its front);\n"
    "# yaw: radians about world y, the front points along world (sin yaw, 0, cos yaw). A world point p\n"
    "# is inside when R_y(yaw)^T (p - center) lies within +-half in every axis.\n";

} // namespace

std::string formatMovingBoxes(const std::vector<MovingBox>& boxes) {
  std::string text = kHeader;
  char line[256];
  for (const MovingBox& b : boxes) {
    // %.9g reads back to the same float, which is what the renderer placed.
    std::snprintf(line, sizeof line, "%zu %u %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", b.frame, b.object, b.center.x(),
                  b.center.y(), b.center.z(), b.half_extents.x(), b.half_extents.y(), b.half_extents.z(), b.yaw);
    text += line;
  }
  return text;
}

std::vector<MovingBox> readMovingBoxes(const std::string& path) {
  std::vector<MovingBox> boxes;
  forEachTextRecord(path, "moving objects", [&](int number, const std::vector<std::string>& fields,
                                                const std::string& line) {
    MovingBox b;
    double v[7];
    bool ok = fields.size() == 9 && parseNumber(fields[0], b.frame) && parseNumber(fields[1], b.object);
    for (int i = 0; ok && i < 7; ++i)
      ok = parseNumber(fields[static_cast<std::size_t>(i) + 2], v[i]) && std::isfinite(v[i]);
    if (!ok || v[3] < 0.0 || v[4] < 0.0 || v[5] < 0.0)
      throw IOError("moving objects '" + path + "' line " + std::to_string(number) +
                    ": expected 'frame object center_x center_y center_z half_x half_y half_z yaw' (two whole "
                    "numbers, seven finite numbers, half extents >= 0), got '" +
                    line + "'");
    b.center = {v[0], v[1], v[2]};
    b.half_extents = {v[3], v[4], v[5]};
    b.yaw = v[6];
    boxes.push_back(b);
  });
  return boxes;
}

} // namespace msf::synthetic
