// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/crumb_metric.h>
#include <msf/reconstruction/mesh_components.h>

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

namespace msf {

namespace {
/// A small piece's vertices, and how many of them lie off the static surface, and where.
struct PieceTally {
  std::size_t triangles = 0, vertices = 0, off_surface = 0, ghosts = 0;
  std::vector<std::size_t> frames_since_left; // of its ghost vertices
};

/// The bucket of a crumb's median age: i + 1 frames in [i], the last bucket open.
std::size_t ageBucket(std::vector<std::size_t>& ages, std::size_t buckets) {
  auto middle = ages.begin() + static_cast<std::ptrdiff_t>(ages.size() / 2);
  std::nth_element(ages.begin(), middle, ages.end());
  return std::min(std::max<std::size_t>(*middle, 1), buckets) - 1;
}
} // namespace

CrumbMetrics measureCrumbs(const TriangleMesh& mesh, const SurfaceDistance& static_truth, const MovingSpace& was_moving,
                           std::size_t max_triangles, double distance_m, const FramesSinceLeft& since_left,
                           std::size_t age_buckets) {
  if (!was_moving)
    throw InvalidInputError("crumb metric: no moving-object space to test the pieces against");
  if (!(distance_m > 0.0))
    throw InvalidInputError("crumb metric: the ghost distance must be > 0 m, not " + std::to_string(distance_m));
  if (max_triangles == 0)
    throw InvalidInputError("crumb metric: a small piece must be allowed at least one triangle");
  if (since_left && age_buckets == 0)
    throw InvalidInputError("crumb metric: the crumbs' ages need at least one bucket");
  CrumbMetrics m;
  if (since_left)
    m.by_frames_since_left.assign(age_buckets, 0);
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
      if (was_moving(mesh.vertices[v])) {
        ++p.ghosts;
        if (since_left)
          p.frames_since_left.push_back(since_left(mesh.vertices[v]));
      }
    }
  }
  for (auto& [label, p] : tally) {
    if (p.triangles >= max_triangles)
      continue;
    ++m.small_pieces;
    if (2 * p.ghosts > p.vertices) {
      ++m.crumbs;
      m.crumb_triangles += p.triangles;
      if (since_left)
        ++m.by_frames_since_left[ageBucket(p.frames_since_left, age_buckets)];
    } else if (2 * p.off_surface > p.vertices) {
      ++m.specks;
    }
  }
  return m;
}

} // namespace msf
