// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>

#include <pcl/PolygonMesh.h>

#include <Eigen/Geometry>
#include <string>

namespace msf {

/// The world the outputs are written in. The map is built in the poses' world: camera 0 of the
/// first frame for KITTI's and the odometry's (x right, y down, z forward), a bag's tf world or
/// a poses file's as they are. `ZUp` turns a world of a camera's axes to x forward, y left, z up
/// (ROS's), and leaves a world that is already z-up as it is.
enum class WorldFrame { Camera, ZUp };

/// "camera" or "z_up"; throws InvalidInputError naming the text otherwise.
WorldFrame parseWorldFrame(const std::string& text);
const char* toString(WorldFrame frame);

/// T_out_world: from the map's world to the output's. The world's up is the camera's (-y) of
/// `T_world_cam0`, the first frame's pose: ZUp leaves a world whose z it is within 45 degrees of
/// as it is (a map frame's), and turns any other as it turns camera 0's axes.
Eigen::Isometry3d outputTransform(WorldFrame frame,
                                  const Eigen::Isometry3d& T_world_cam0 = Eigen::Isometry3d::Identity());
/// Whether the world of a camera at `T_world_cam0` is already z-up (outputTransform).
bool worldIsZUp(const Eigen::Isometry3d& T_world_cam0);

/// The mesh's points (x, y, z, and normal_x/y/z when present) moved by T, in place.
void transformMesh(pcl::PolygonMesh& mesh, const Eigen::Isometry3d& T);
/// The poses T_world_cam as T_out_cam = T * T_world_cam (the camera's own axes unchanged).
PoseList transformPoses(const PoseList& T_world_cam, const Eigen::Isometry3d& T_out_world);

} // namespace msf
