// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/registration/plane_fit.h>

#include <Eigen/Eigenvalues>

namespace msf {

bool fitPlane(const PointMoments& moments, double min_spread_m, PlaneFit& plane) {
  if (moments.count < 5)
    return false;
  const Eigen::Vector3d mean = moments.sum / moments.count;
  const Eigen::Matrix3d outer = moments.outer.selfadjointView<Eigen::Upper>();
  const Eigen::Matrix3d cov = outer / moments.count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  const Eigen::Vector3d l = eig.eigenvalues(); // ascending variances
  if (l[1] < min_spread_m * min_spread_m || l[0] * 49.0 > l[1])
    return false;
  plane.mean = mean;
  plane.normal = eig.eigenvectors().col(0);
  return true;
}

} // namespace msf
