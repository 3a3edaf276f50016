// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/world_frame.h>

#include <cmath>
#include <cstring>

namespace msf {

WorldFrame parseWorldFrame(const std::string& text) {
  if (text == "camera")
    return WorldFrame::Camera;
  if (text == "z_up")
    return WorldFrame::ZUp;
  throw InvalidInputError("world frame must be camera (the poses' world: KITTI's is camera 0 of the first frame) or "
                          "z_up (x forward, y left, z up), not '" + text + "'");
}

const char* toString(WorldFrame frame) { return frame == WorldFrame::ZUp ? "z_up" : "camera"; }

bool worldIsZUp(const Eigen::Isometry3d& T_world_cam0) {
  const Eigen::Vector3d camera_up = T_world_cam0.linear() * Eigen::Vector3d(0, -1, 0);
  return camera_up.z() > std::cos(M_PI / 4);
}

Eigen::Isometry3d outputTransform(WorldFrame frame, const Eigen::Isometry3d& T_world_cam0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (frame == WorldFrame::ZUp && !worldIsZUp(T_world_cam0))
    T.linear() << 0, 0, 1, // x: forward, the camera's z
        -1, 0, 0,          // y: left, the camera's -x
        0, -1, 0;          // z: up, the camera's -y
  return T;
}

void transformMesh(pcl::PolygonMesh& mesh, const Eigen::Isometry3d& T) {
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  auto offsetOf = [&](const char* name) -> int {
    for (const auto& f : cloud.fields)
      if (f.name == name) {
        if (f.datatype != pcl::PCLPointField::FLOAT32)
          throw InvalidInputError(std::string("transformMesh: field ") + name + " is not float32");
        return static_cast<int>(f.offset);
      }
    return -1;
  };
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const auto apply = [&](const char* x, const char* y, const char* z, bool translate) {
    const int ox = offsetOf(x), oy = offsetOf(y), oz = offsetOf(z);
    if (ox < 0 || oy < 0 || oz < 0)
      return;
    const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
    for (std::size_t k = 0; k < n; ++k) {
      std::uint8_t* p = cloud.data.data() + k * cloud.point_step;
      Eigen::Vector3f v;
      std::memcpy(&v[0], p + ox, 4);
      std::memcpy(&v[1], p + oy, 4);
      std::memcpy(&v[2], p + oz, 4);
      v = translate ? Eigen::Vector3f(R * v + t) : Eigen::Vector3f(R * v);
      std::memcpy(p + ox, &v[0], 4);
      std::memcpy(p + oy, &v[1], 4);
      std::memcpy(p + oz, &v[2], 4);
    }
  };
  apply("x", "y", "z", true);
  apply("normal_x", "normal_y", "normal_z", false);
}

PoseList transformPoses(const PoseList& T_world_cam, const Eigen::Isometry3d& T_out_world) {
  PoseList out;
  out.reserve(T_world_cam.size());
  for (const auto& T : T_world_cam)
    out.push_back(T_out_world * T);
  return out;
}

} // namespace msf
