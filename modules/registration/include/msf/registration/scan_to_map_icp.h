// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/local_map.h>
#include <msf/registration/nearest_cache.h>
#include <msf/registration/point_list.h>

#include <Eigen/Geometry>

#include <cstddef>

namespace msf {

/// One registration of a scan to the local map: Gauss-Newton on the distance of each point
/// to its nearest map point, or to that point's plane where its voxel is planar
/// (point_to_plane), pairs farther than max_correspondence_m dropped and the rest weighed by
/// a Geman-McClure kernel of scale kernel_scale_m, so that what moved (a car) or was not seen
/// before pulls little. A plane lets a point slide along the surface it lies on: on a road
/// seen ring by ring, the nearest map point is on the ring of an earlier scan, and
/// point-to-point distances pull the scan back towards where that scan was taken.
/// A measured pose of the scan (a GPS/INS's), a soft constraint on the registration: the
/// registered pose's error in the measured pose's frame is weighed as a Gaussian of these
/// standard deviations, each scan pair as a measurement whose standard deviation is the robust
/// kernel's scale. The scans win in every direction their planes pin down; where they pin
/// none (a tunnel's axis, an open field) the measured pose holds.
struct PosePrior {
  Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
  double translation_sigma_m = 0.1;
  double rotation_sigma_rad = 0.002;
};

struct IcpSettings {
  double max_correspondence_m = 2.0;
  double kernel_scale_m = 0.66;
  bool point_to_plane = true;
  /// Planes only, no point-to-point pair (point_to_plane on).
  bool planes_only = false;
  int max_iterations = 100;
  /// Stops when an update moves the pose by less than this (metres plus radians).
  double convergence = 1e-4;
  /// The measured pose, or nullptr for none. With one, a scan without pairs within reach
  /// registers at the measured pose instead of being an error.
  const PosePrior* prior = nullptr;
};

struct IcpResult {
  Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
  int iterations = 0;
  std::size_t correspondences = 0;  ///< pairs of the last iteration
  std::size_t planes = 0;           ///< of which point-to-plane
  bool converged = false;           ///< the last update was below `convergence`
};

/// Aligns `points_sensor` (a scan in its sensor's frame) to `map`, from `initial_guess`.
/// Throws InvalidInputError when fewer than 6 points find a map point within reach and there
/// is no prior.
/// `neighbors`, when given, is the NearestCache used (its memory kept for the next call).
IcpResult alignScanToMap(const PointList& points_sensor, const LocalMap& map, const Eigen::Isometry3d& initial_guess,
                         const IcpSettings& settings, NearestCache* neighbors = nullptr);

} // namespace msf
