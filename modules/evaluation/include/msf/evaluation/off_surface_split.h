// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/lidar_support.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/reconstruction/marching_cubes.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace msf {

/// The area of a mesh off every true surface, split by its height above the ground and by
/// whether a LiDAR return was ever near it: sheets in the sky stand high and unsupported,
/// ghosts of cars low, the fattened edges of trunks and signs in between.
struct OffSurfaceSplit {
  /// One band of heights above the ground, [lower_m, upper_m), and the off-surface area in it.
  struct Band {
    double lower_m = 0, upper_m = 0;   ///< the lowest band starts at -inf, the highest ends at +inf
    double supported_m2 = 0;           ///< triangles with a LiDAR return near them (LidarSupport)
    double unsupported_m2 = 0;         ///< triangles with none
  };
  double distance_m = 0;    ///< a triangle farther than this from the true surface is off it
  double area_m2 = 0;       ///< the whole mesh
  double off_area_m2 = 0;   ///< the triangles off the true surface
  std::vector<Band> bands;  ///< from the lowest up; their areas add up to off_area_m2

  /// off_area_m2 / area_m2, 0 without area.
  double offShare() const;
  /// A part of the off-surface area as a share of it, 0 without any.
  double shareOfOff(double area) const;
};

/// Splits `mesh` (world frame): a triangle is off the surface when its centroid lies farther
/// than `distance_m` from `truth`; its height is the centroid's signed distance to `ground`
/// (the normal pointing up); it is supported when `support` has a return near the centroid.
/// `band_edges_m` (rising) cut the heights into bands, e.g. {2, 5}: below 2 m, 2-5 m, above 5 m.
/// Throws InvalidInputError for a distance that is not > 0, edges that do not rise, or a mesh
/// index out of range.
OffSurfaceSplit splitOffSurface(const TriangleMesh& mesh, const SurfaceDistance& truth,
                                const Eigen::Hyperplane<float, 3>& ground, const LidarSupport& support,
                                double distance_m, const std::vector<double>& band_edges_m);

} // namespace msf
