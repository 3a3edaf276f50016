// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/registration/scan_constraints.h>
#include <msf/registration/plane_fit.h>
#include <msf/registration/voxel_downsample.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>
#include <vector>

namespace msf {

int ScanConstraints::unconstrained(double min_eigenvalue) const {
  if (patches == 0)
    return 6;
  int n = 0;
  for (int k = 0; k < 6; ++k)
    n += eigenvalues[k] <= min_eigenvalue;
  return n;
}

std::string ScanConstraints::weakestDirection() const {
  if (patches == 0)
    return "all (no planar patch)";
  const Eigen::Matrix<double, 6, 1> v = eigenvectors.col(0);
  const bool rotation = v.tail<3>().norm() > v.head<3>().norm();
  Eigen::Vector3d axis = rotation ? v.tail<3>() : v.head<3>();
  axis.normalize();
  Eigen::Index largest = 0;
  axis.cwiseAbs().maxCoeff(&largest);
  if (axis[largest] < 0) // an eigenvector's sign is arbitrary: print the same one each time
    axis = -axis;
  char text[96];
  const Eigen::Vector3d rounded = (100.0 * axis).array().round() / 100.0 + 0.0; // no "-0.00"
  std::snprintf(text, sizeof text, "%s (%.2f, %.2f, %.2f)", rotation ? "rotation about" : "translation along",
                rounded.x(), rounded.y(), rounded.z());
  return text;
}

ScanConstraints analyzeConstraints(const PointList& points_sensor, double patch_size_m) {
  // The patches' moments: one voxel of patch_size_m each, about its first point.
  std::vector<PointMoments> moments;
  const PointList firsts = voxelDownsample(points_sensor, patch_size_m, &moments);
  struct Patch {
    Eigen::Vector3d centre, normal;
  };
  std::vector<Patch> patches;
  double sum_r2 = 0.0;
  for (std::size_t k = 0; k < firsts.size(); ++k) {
    PlaneFit plane;
    if (!fitPlane(moments[k], 0.1 * patch_size_m, plane))
      continue;
    patches.push_back({firsts[k] + plane.mean, plane.normal});
    sum_r2 += patches.back().centre.squaredNorm();
  }

  ScanConstraints result;
  result.patches = patches.size();
  result.eigenvalues.setZero();
  result.eigenvectors.setIdentity();
  if (patches.empty())
    return result;
  result.lever_m = std::sqrt(sum_r2 / static_cast<double>(patches.size()));
  const double inv_lever = result.lever_m > 0 ? 1.0 / result.lever_m : 0.0;
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (const Patch& patch : patches) {
    Eigen::Matrix<double, 6, 1> j;
    j << patch.normal, patch.centre.cross(patch.normal) * inv_lever;
    information += j * j.transpose();
  }
  information /= static_cast<double>(patches.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(information);
  result.eigenvalues = eig.eigenvalues();
  result.eigenvectors = eig.eigenvectors();
  return result;
}

} // namespace msf
