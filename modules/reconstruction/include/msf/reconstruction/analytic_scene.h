// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/depth_frame.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <vector>

namespace msf {

/// A small scene of analytic solids (half-spaces, spheres, oriented boxes) with exact ray
/// casting and exact distances: the ground truth of the TSDF tests and of the lambda study
/// (paper Fig. 5). The scene is the union of the solids; cameras must be outside it.
class AnalyticScene {
public:
  /// The half-space n . p <= offset (n is normalised), e.g. a ground plane.
  void addHalfSpace(const Eigen::Vector3d& normal, double offset);
  void addSphere(const Eigen::Vector3d& center, double radius);
  /// A box with half extents `half`, rotated by `rotation` about its centre.
  void addBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half,
              const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity());

  /// Exact depth (z in the camera, metres; 0 where nothing is hit within max_depth) seen
  /// from T_world_cam through `camera`, one ray per pixel centre.
  cv::Mat renderDepth(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, double max_depth) const;

  /// Signed distance to the union's surface (negative inside): exact outside the solids, the
  /// usual min of the solids' distances inside.
  double signedDistance(const Eigen::Vector3d& p) const;

private:
  struct Solid {
    enum class Kind { HalfSpace, Sphere, Box } kind;
    Eigen::Vector3d a;  // normal | centre | centre
    Eigen::Vector3d b;  // (offset, 0, 0) | (radius, 0, 0) | half extents
    Eigen::Matrix3d R;  // box rotation (box frame to world)
  };
  /// Ray parameter where the ray o + t d enters the solid (t > 0), or +inf.
  static double hit(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d);
  static double distance(const Solid& s, const Eigen::Vector3d& p);

  std::vector<Solid> solids_;
};

} // namespace msf
