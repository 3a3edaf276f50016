// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/ghost_metric.h>
#include <msf/reconstruction/marching_cubes.h>

#include <cstddef>

namespace msf {

/// Crumbs of moving objects in a map: the small pieces a moving object's carved-away ghost
/// leaves behind, which a person sees as specks along its lane.
struct CrumbMetrics {
  std::size_t pieces = 0;          ///< connected pieces of the mesh
  std::size_t small_pieces = 0;    ///< of those, with fewer than max_triangles triangles
  std::size_t crumbs = 0;          ///< small pieces that are mostly ghost (see measureCrumbs)
  std::size_t crumb_triangles = 0; ///< their triangles
  std::size_t specks = 0;          ///< small pieces mostly off the static surface elsewhere
  std::size_t max_triangles = 0;   ///< what "small" means
  double distance_m = 0;           ///< the distance from the static surface that makes a ghost
};

/// Counts the connected pieces of `mesh` (world frame) with fewer than `max_triangles`
/// triangles whose vertices lie, more than half of them, farther than `distance_m` from the
/// static true surface: crumbs where a moving object was (`was_moving`, as measureGhosts),
/// specks elsewhere. A small static object (a bollard, a sign) lies on the static surface and
/// counts as neither. Throws InvalidInputError when `was_moving` is empty, distance_m is not
/// > 0 or max_triangles is 0.
CrumbMetrics measureCrumbs(const TriangleMesh& mesh, const SurfaceDistance& static_truth, const MovingSpace& was_moving,
                           std::size_t max_triangles = 50, double distance_m = 0.2);

} // namespace msf
