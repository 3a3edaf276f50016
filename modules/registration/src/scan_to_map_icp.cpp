// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/registration/scan_to_map_icp.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <string>

namespace msf {

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// exp of a twist [translation; rotation vector] as an isometry (rotation by Rodrigues).
Eigen::Isometry3d exponential(const Vector6d& delta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d omega = delta.tail<3>();
  const double angle = omega.norm();
  if (angle > 0.0)
    T.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  T.translation() = delta.head<3>();
  return T;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// Adds the prior's Gauss-Newton term at T to H and g, for the left update T <- exp(delta) T:
/// the error E = P^-1 T as e = [E_t; log E_R], whose Jacobian is [[R_p^T, -R_p^T [t]x], [0, R^T]],
/// weighed by the prior's information in units of a scan pair's (point_sigma_m).
void addPrior(const PosePrior& prior, const Eigen::Isometry3d& T, double point_sigma_m, Matrix6d& H, Vector6d& g) {
  const Eigen::Isometry3d E = prior.T_world_sensor.inverse() * T;
  const Eigen::AngleAxisd rotation(E.linear());
  Vector6d e;
  e << E.translation(), rotation.angle() * rotation.axis();
  const Eigen::Matrix3d R_p_t = prior.T_world_sensor.linear().transpose();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = R_p_t;
  J.topRightCorner<3, 3>() = -R_p_t * skew(T.translation());
  J.bottomRightCorner<3, 3>() = T.linear().transpose();
  const double s2 = point_sigma_m * point_sigma_m;
  Vector6d information;
  information << Eigen::Vector3d::Constant(s2 / (prior.translation_sigma_m * prior.translation_sigma_m)),
      Eigen::Vector3d::Constant(s2 / (prior.rotation_sigma_rad * prior.rotation_sigma_rad));
  H += J.transpose() * information.asDiagonal() * J;
  g += J.transpose() * information.asDiagonal() * e;
}

/// The normal equations of one iteration, for a left update T <- exp(delta) T. A point
/// w = T p moves by delta_t + delta_r x w: the point residual's Jacobian is [I, -[w]x], the
/// plane residual's n^T [I, -[w]x] = [n^T, (w x n)^T]. The point terms are summed in 3x3
/// blocks, not as 6x6 products per point; each pair is weighed by a Geman-McClure kernel.
struct NormalEquations {
  Eigen::Matrix3d H_tt = Eigen::Matrix3d::Zero(), H_tr = Eigen::Matrix3d::Zero(), H_rr = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g_t = Eigen::Vector3d::Zero(), g_r = Eigen::Vector3d::Zero();
  Matrix6d H_plane = Matrix6d::Zero(); // its upper triangle
  Vector6d g_plane = Vector6d::Zero();
  std::size_t pairs = 0, planes = 0;

  /// A point w paired with its neighbour's plane.
  void addPlane(const Eigen::Vector3d& w, const LocalMap::Neighbor& neighbor, double scale2) {
    const double e = neighbor.normal.dot(w - neighbor.plane_point);
    const double weight = 1.0 / ((1.0 + e * e / scale2) * (1.0 + e * e / scale2));
    Vector6d J;
    J << neighbor.normal, w.cross(neighbor.normal);
    for (int c = 0; c < 6; ++c) // the upper triangle, by hand: Eigen's rankUpdate is a call per point
      for (int r = 0; r <= c; ++r)
        H_plane(r, c) += weight * J[r] * J[c];
    g_plane += weight * e * J;
    ++planes;
  }

  /// A point w paired with its neighbour's point.
  void addPoint(const Eigen::Vector3d& w, const LocalMap::Neighbor& neighbor, double scale2) {
    const double d2 = neighbor.distance2;
    const double weight = 1.0 / ((1.0 + d2 / scale2) * (1.0 + d2 / scale2));
    const Eigen::Vector3d r = w - neighbor.point;
    const Eigen::Matrix3d W = skew(w);
    H_tt.diagonal().array() += weight;
    H_tr -= weight * W;
    H_rr -= weight * W * W;
    g_t += weight * r;
    g_r += weight * w.cross(r); // (-[w]x)^T r = [w]x r
  }

  /// The whole H and g.
  void assemble(Matrix6d& H, Vector6d& g) const {
    H << H_tt, H_tr, H_tr.transpose(), H_rr;
    H += H_plane.selfadjointView<Eigen::Upper>();
    g << g_t, g_r;
    g += g_plane;
  }
};

/// The points at their positions `world` paired with the map's nearest points (or planes).
NormalEquations pairWithMap(const PointList& world, NearestCache& cache, const IcpSettings& settings) {
  const double scale2 = settings.kernel_scale_m * settings.kernel_scale_m;
  NormalEquations equations;
  LocalMap::Neighbor neighbor;
  const std::size_t n = world.size();
  // The table's slots that the search of the point kAhead places on will read are fetched
  // while this one is searched.
  constexpr std::size_t kAhead = 12;
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n)
      cache.prefetch(i + kAhead, world[i + kAhead]);
    const Eigen::Vector3d& w = world[i];
    if (!cache.nearest(i, w, neighbor))
      continue;
    if (settings.point_to_plane && neighbor.planar) {
      ++equations.pairs;
      equations.addPlane(w, neighbor, scale2);
    } else if (!settings.planes_only) {
      ++equations.pairs;
      equations.addPoint(w, neighbor, scale2);
    }
  }
  return equations;
}

/// The Gauss-Newton step at T: the pairs' normal equations and, when there is one, the prior's.
Vector6d gaussNewtonStep(const NormalEquations& equations, const IcpSettings& settings, const Eigen::Isometry3d& T) {
  Matrix6d H;
  Vector6d g;
  equations.assemble(H, g);
  if (settings.prior)
    addPrior(*settings.prior, T, settings.kernel_scale_m, H, g);
  return H.ldlt().solve(-g);
}

} // namespace

IcpResult alignScanToMap(const PointList& points_sensor, const LocalMap& map, const Eigen::Isometry3d& initial_guess,
                         const IcpSettings& settings, NearestCache* neighbors) {
  IcpResult result;
  result.T_world_sensor = initial_guess;
  if (map.empty()) { // no pair: the prior alone, or nothing to align to
    if (!settings.prior)
      throw InvalidInputError("scan-to-map ICP: the map is empty; no point of " + std::to_string(points_sensor.size()) +
                              " has a map point within " + std::to_string(settings.max_correspondence_m) + " m");
    result.T_world_sensor = settings.prior->T_world_sensor;
    result.converged = true;
    return result;
  }
  // After the first iteration the points move by millimetres: most keep their neighbour.
  NearestCache own;
  NearestCache& cache = neighbors ? *neighbors : own;
  cache.reset(map, settings.max_correspondence_m, points_sensor.size());
  PointList world(points_sensor.size()); // the points in the world at the iteration's pose
  for (result.iterations = 1; result.iterations <= settings.max_iterations; ++result.iterations) {
    for (std::size_t i = 0; i < points_sensor.size(); ++i)
      world[i] = result.T_world_sensor * points_sensor[i];
    const NormalEquations equations = pairWithMap(world, cache, settings);
    result.correspondences = equations.pairs;
    result.planes = equations.planes;
    if (equations.pairs < 6 && !settings.prior)
      throw InvalidInputError("scan-to-map ICP: " + std::to_string(equations.pairs) + " of " +
                              std::to_string(points_sensor.size()) + " points have a map point within " +
                              std::to_string(settings.max_correspondence_m) + " m; at least 6 are needed");
    const Vector6d delta = gaussNewtonStep(equations, settings, result.T_world_sensor);
    result.T_world_sensor = exponential(delta) * result.T_world_sensor;
    // Back onto the rotations: rounding leaves R slightly off, and the constant-velocity
    // prediction (which inverts by transposing) would double that every frame.
    result.T_world_sensor.linear() = Eigen::Quaterniond(result.T_world_sensor.linear()).normalized().toRotationMatrix();
    if (delta.norm() < settings.convergence) {
      result.converged = true;
      break;
    }
  }
  result.iterations = std::min(result.iterations, settings.max_iterations);
  return result;
}

} // namespace msf
