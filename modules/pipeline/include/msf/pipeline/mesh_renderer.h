// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/marching_cubes.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

namespace msf {

/// Previews of a mesh (no display or GPU needed): the surface MeshRasterizer sees at each
/// pixel in its vertex colours, shaded by how squarely it faces the viewer, on a dark background.
class MeshRenderer {
public:
  /// BGR of pixels no triangle covers: a dark slate, against which bright surfaces (a sunlit
  /// road) stand out, and a part of the scene that has no mesh is not taken for one.
  static inline const cv::Scalar kBackground{72, 56, 48};

  /// Perspective view through a pinhole camera at T_world_cam (x right, y down, z forward).
  static cv::Mat render(const TriangleMesh& mesh, const Eigen::Isometry3d& T_world_cam, double fx, double fy,
                        double cx, double cy, cv::Size size);

  /// View from above: a camera looking down the world's `up` axis at the mesh's bounding
  /// box, framing all of it. `up` is the world direction that points to the sky (for KITTI
  /// camera-0 poses, -y).
  static cv::Mat renderFromAbove(const TriangleMesh& mesh, const Eigen::Vector3d& up, cv::Size size);
};

} // namespace msf
