// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Analytic scenes and cameras shared by the reconstruction tests.
#include <msf/reconstruction/analytic_scene.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

namespace msf::test {

/// A pinhole camera of `width` x `height` pixels, focal length `f` pixels, centred.
inline PinholeCamera centredCamera(int width, int height, double f) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = f;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

inline PinholeCamera smallCamera() { return centredCamera(320, 240, 300.0); }

/// Camera at `eye` looking at `target` (camera x right, y down, z forward; world y down too).
inline Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized(); // y down: x = y cross z
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

/// `n` cameras on an arc of +-`degrees` about the vertical axis through `target`, at `radius`.
inline std::vector<Eigen::Isometry3d> arcPoses(const Eigen::Vector3d& target, double radius, double degrees, int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i) {
    const double a = n == 1 ? 0.0 : (-degrees + 2.0 * degrees * i / (n - 1)) * M_PI / 180.0;
    const Eigen::Vector3d eye = target + Eigen::Vector3d(radius * std::sin(a), -0.3, -radius * std::cos(a));
    poses.push_back(lookAt(eye, target));
  }
  return poses;
}

enum class SceneKind { Plane, Sphere, Box };

inline AnalyticScene makeScene(SceneKind kind) {
  AnalyticScene scene;
  switch (kind) {
  case SceneKind::Plane: // a slanted wall
    scene.addHalfSpace(Eigen::Vector3d(0.3, -0.2, -1.0), -3.0);
    break;
  case SceneKind::Sphere:
    scene.addSphere(Eigen::Vector3d(0, 0, 2.5), 0.5);
    scene.addHalfSpace(Eigen::Vector3d(0, 0, -1), -3.6);
    break;
  case SceneKind::Box:
    scene.addBox(Eigen::Vector3d(0, 0, 2.5), Eigen::Vector3d(0.3, 0.3, 0.3),
                 (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix());
    scene.addHalfSpace(Eigen::Vector3d(0, 0, -1), -3.6);
    break;
  }
  return scene;
}

/// A corridor along +z (world y down): a floor, two walls 4 m off the axis, and boxes on
/// either side every few metres, each a little different, so that no two tiles look alike.
inline AnalyticScene corridor(double length, double wall = 4.0) {
  AnalyticScene scene;
  scene.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.5);  // floor: y >= 1.5
  scene.addHalfSpace(Eigen::Vector3d(-1, 0, 0), -wall); // x >= wall
  scene.addHalfSpace(Eigen::Vector3d(1, 0, 0), -wall);  // x <= -wall
  for (int i = 0; i * 3.0 < length; ++i) {
    const double side = i % 2 ? 1.0 : -1.0;
    scene.addBox(Eigen::Vector3d(side * (wall - 1.2 - 0.1 * (i % 3)), 1.0, 3.0 * i + 1.0),
                 Eigen::Vector3d(0.5, 0.5 + 0.1 * (i % 4), 0.4 + 0.05 * (i % 5)),
                 Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitY()).toRotationMatrix());
  }
  return scene;
}

/// KITTI's camera 0 (odometry sequence 04).
inline PinholeCamera kittiCamera() {
  PinholeCamera c;
  c.width = 1241;
  c.height = 376;
  c.fx = c.fy = 718.856f;
  c.cx = 607.19f;
  c.cy = 185.22f;
  return c;
}

/// Depth frame of `scene` from `pose`, with Gaussian depth noise of `sigma` metres.
inline DepthFrame renderFrame(const AnalyticScene& scene, const PinholeCamera& camera, const Eigen::Isometry3d& pose,
                              double sigma = 0.0, unsigned seed = 1) {
  DepthFrame frame;
  frame.camera = camera;
  frame.depth = scene.renderDepth(camera, pose, 20.0);
  if (sigma > 0) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.f, static_cast<float>(sigma));
    for (int v = 0; v < frame.depth.rows; ++v)
      for (int u = 0; u < frame.depth.cols; ++u) {
        float& d = frame.depth.at<float>(v, u);
        if (d > 0)
          d += noise(rng);
      }
  }
  return frame;
}

/// Mean |true signed distance| of the mesh vertices, in metres.
inline double meanVertexError(const AnalyticScene& scene, const TriangleMesh& mesh) {
  double sum = 0;
  for (const auto& v : mesh.vertices)
    sum += std::abs(scene.signedDistance(v.cast<double>()));
  return mesh.vertices.empty() ? 1e9 : sum / static_cast<double>(mesh.vertices.size());
}

} // namespace msf::test
