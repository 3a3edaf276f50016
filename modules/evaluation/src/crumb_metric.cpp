// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/crumb_metric.h>
#include <msf/reconstruction/mesh_components.h>

#include <string>
#include <unordered_map>
#include <vector>

namespace msf {

namespace {
/// A small piece's vertices, and how many of them lie off the static surface, and where.
struct PieceTally {
  std::size_t triangles = 0, vertices = 0, off_surface = 0, ghosts = 0;
};
} // namespace

CrumbMetrics measureCrumbs(const TriangleMesh& mesh, const SurfaceDistance& static_truth, const MovingSpace& was_moving,
                           std::size_t max_triangles, double distance_m) {
  if (!was_moving)
    throw InvalidInputError("crumb metric: no moving-object space to test the pieces against");
  if (!(distance_m > 0.0))
    throw InvalidInputError("crumb metric: the ghost distance must be > 0 m, not " + std::to_string(distance_m));
  if (max_triangles == 0)
    throw InvalidInputError("crumb metric: a small piece must be allowed at least one triangle");
  CrumbMetrics m;
  m.max_triangles = max_triangles;
  m.distance_m = distance_m;
  const std::vector<std::uint32_t> piece = componentLabels(mesh);
  std::unordered_map<std::uint32_t, PieceTally> tally;
  for (const auto& t : mesh.triangles)
    ++tally[piece[t[0]]].triangles;
  m.pieces = tally.size();

  // Only the small pieces' vertices are tested against the surface: they are few.
  const auto d = static_cast<float>(distance_m);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto it = tally.find(piece[v]);
    if (it == tally.end() || it->second.triangles >= max_triangles)
      continue;
    PieceTally& p = it->second;
    ++p.vertices;
    if (static_truth.distance(mesh.vertices[v], 2.f * d) > d) {
      ++p.off_surface;
      p.ghosts += was_moving(mesh.vertices[v]);
    }
  }
  for (const auto& [label, p] : tally) {
    if (p.triangles >= max_triangles)
      continue;
    ++m.small_pieces;
    if (2 * p.ghosts > p.vertices) {
      ++m.crumbs;
      m.crumb_triangles += p.triangles;
    } else if (2 * p.off_surface > p.vertices) {
      ++m.specks;
    }
  }
  return m;
}

} // namespace msf
