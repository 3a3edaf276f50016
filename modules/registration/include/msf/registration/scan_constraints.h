// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/point_list.h>

#include <Eigen/Core>

#include <cstddef>
#include <string>

namespace msf {

/// How well a scan pins down each of the six degrees of freedom of its pose, from the planes
/// it sees: an empty road constrains only height, roll and pitch, and registering it would
/// return whatever the prediction said for the other three (a wrong trajectory that looks
/// right). Each planar patch contributes the point-to-plane information of its normal n at
/// its centre c: [n; c x n / L], L the RMS distance of the patches from the sensor so that a
/// rotation counts as the metres it moves points at that distance. The 6x6 information is
/// normalised by the number of patches: its eigenvalues are between 0 (a direction no patch
/// constrains) and 1.
struct ScanConstraints {
  std::size_t patches = 0;                   ///< planar patches found
  Eigen::Matrix<double, 6, 1> eigenvalues;   ///< ascending
  Eigen::Matrix<double, 6, 6> eigenvectors;  ///< columns: [translation; rotation * L]
  double lever_m = 0;                        ///< L

  /// The smallest eigenvalue; 0 without patches.
  double weakest() const { return patches ? eigenvalues[0] : 0.0; }
  /// The eigenvalues at or below `min_eigenvalue`: the unconstrained degrees of freedom.
  int unconstrained(double min_eigenvalue) const;
  /// The weakest direction in words: "translation (0.00, 1.00, 0.00)" or "rotation about ...".
  std::string weakestDirection() const;
};

/// Planar patches of `points_sensor` (a scan in its sensor's frame) in voxels of patch_size_m
/// (fitPlane, spread over a tenth of a patch).
ScanConstraints analyzeConstraints(const PointList& points_sensor, double patch_size_m);

} // namespace msf
