// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>

#include <vector>

namespace msf {

/// Points of the odometry, in double: world coordinates grow with the drive, and a pose is
/// the sum of thousands of them.
using PointList = std::vector<Eigen::Vector3d>;

} // namespace msf
