// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/mesh_accuracy.h>

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <vector>

namespace msf {

/// Ghosts of moving objects in a map: surface a moving object left where no static surface
/// is (a car integrated at its place in a few frames and never carved away).
struct GhostMetrics {
  std::size_t vertices = 0;        ///< mesh vertices examined
  std::size_t ghost_vertices = 0;  ///< of those, ghosts
  double share = 0;                ///< ghost_vertices / vertices (0 without vertices)
  double distance_m = 0;           ///< the distance from the static surface that makes a ghost
};

/// Where a moving object was at some frame of the sequence (world frame), e.g. inside the
/// box of a moving car at any frame.
using MovingSpace = std::function<bool(const Eigen::Vector3f&)>;

/// The share of `vertices` (world frame) that are farther than `distance_m` from the static
/// true surface and inside the space a moving object occupied (`was_moving`): far from the
/// static surface alone is a speck or a wrong surface, not a ghost; inside a moving object's
/// space alone is the road under it. `was_moving` is called once per vertex, from this
/// thread. Throws InvalidInputError when `was_moving` is empty or distance_m is not > 0.
GhostMetrics measureGhosts(const std::vector<Eigen::Vector3f>& vertices, const SurfaceDistance& static_truth,
                           const MovingSpace& was_moving, double distance_m = 0.2);

} // namespace msf
