// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/ghost_metric.h>

#include <string>

namespace msf {

GhostMetrics measureGhosts(const std::vector<Eigen::Vector3f>& vertices, const SurfaceDistance& static_truth,
                           const MovingSpace& was_moving, double distance_m) {
  if (!was_moving)
    throw InvalidInputError("ghost metric: no moving-object space to test the vertices against");
  if (!(distance_m > 0.0))
    throw InvalidInputError("ghost metric: the ghost distance must be > 0 m, not " + std::to_string(distance_m));
  GhostMetrics m;
  m.vertices = vertices.size();
  m.distance_m = distance_m;
  const auto d = static_cast<float>(distance_m);
  for (const Eigen::Vector3f& p : vertices)
    // The cheap test first: few vertices are where a moving object was.
    if (was_moving(p) && static_truth.distance(p, 2.f * d) > d)
      ++m.ghost_vertices;
  m.share = m.vertices ? static_cast<double>(m.ghost_vertices) / static_cast<double>(m.vertices) : 0.0;
  return m;
}

} // namespace msf
