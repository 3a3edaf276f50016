// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/ghost_metric.h>
#include <msf/reconstruction/marching_cubes.h>

#include <cstddef>
#include <functional>
#include <vector>

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
  /// The crumbs by how many frames before the last one the moving object left their place: [i]
  /// counts i + 1 frames, the last entry that many or more (empty when not measured). A place
  /// left a frame ago has been looked through by one frame at most.
  std::vector<std::size_t> by_frames_since_left;
};

/// How many frames before the last one a moving object left the place `p` (world frame): 0
/// where none ever was or one stands at the last frame.
using FramesSinceLeft = std::function<std::size_t(const Eigen::Vector3f&)>;

/// Counts the connected pieces of `mesh` (world frame) with fewer than `max_triangles`
/// triangles whose vertices lie, more than half of them, farther than `distance_m` from the
/// static true surface: crumbs where a moving object was (`was_moving`, as measureGhosts),
/// specks elsewhere. A small static object (a bollard, a sign) lies on the static surface and
/// counts as neither. With `since_left`, each crumb is also counted by the median over its ghost
/// vertices of the frames since their place was left, in `age_buckets` buckets (the last one
/// open). Throws InvalidInputError when `was_moving` is empty, distance_m is not > 0,
/// max_triangles is 0, or `since_left` is given without buckets.
CrumbMetrics measureCrumbs(const TriangleMesh& mesh, const SurfaceDistance& static_truth, const MovingSpace& was_moving,
                           std::size_t max_triangles = 50, double distance_m = 0.2,
                           const FramesSinceLeft& since_left = {}, std::size_t age_buckets = 3);

} // namespace msf
