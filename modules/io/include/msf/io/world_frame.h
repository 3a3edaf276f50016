// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>

#include <pcl/PolygonMesh.h>

#include <Eigen/Geometry>
#include <string>

namespace msf {

/// The world the outputs are written in. The map is built in camera 0 of the first frame
/// (x right, y down, z forward: KITTI's); `ZUp` turns it to x forward, y left, z up (ROS's).
enum class WorldFrame { Camera, ZUp };

/// "camera" or "z_up"; throws InvalidInputError naming the text otherwise.
WorldFrame parseWorldFrame(const std::string& text);
const char* toString(WorldFrame frame);

/// T_out_world: from the map's world (camera 0 of the first frame) to the output's.
Eigen::Isometry3d outputTransform(WorldFrame frame);

/// The mesh's points (x, y, z, and normal_x/y/z when present) moved by T, in place.
void transformMesh(pcl::PolygonMesh& mesh, const Eigen::Isometry3d& T);
/// The poses T_world_cam as T_out_cam = T * T_world_cam (the camera's own axes unchanged).
PoseList transformPoses(const PoseList& T_world_cam, const Eigen::Isometry3d& T_out_world);

} // namespace msf
