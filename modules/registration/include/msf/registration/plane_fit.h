// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/voxel_downsample.h>

#include <Eigen/Core>

namespace msf {

struct PlaneFit {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();    ///< about the moments' origin
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

/// The plane of the points of `moments` (about some origin), when they lie on one: at least 5,
/// spread by min_spread_m (RMS) or more in two directions and 7 times less in the third. A
/// surface, then; not an edge, a corner, a pole or a single ring of a scan.
bool fitPlane(const PointMoments& moments, double min_spread_m, PlaneFit& plane);

} // namespace msf
