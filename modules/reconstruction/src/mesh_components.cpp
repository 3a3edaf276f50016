// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/reconstruction/mesh_components.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

namespace msf {

namespace {
/// Union-find over vertex indices, with path halving; a root is its piece's smallest vertex.
class DisjointSets {
public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t v) {
    while (parent_[v] != v) {
      parent_[v] = parent_[parent_[v]];
      v = parent_[v];
    }
    return v;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a < b)
      parent_[b] = a;
    else if (b < a)
      parent_[a] = b;
  }

private:
  std::vector<std::uint32_t> parent_;
};
} // namespace

ComponentFilterStats removeSmallComponents(TriangleMesh& mesh, std::size_t min_triangles, float keep_weight) {
  const std::size_t n = mesh.vertices.size();
  if (mesh.colors.size() != n)
    throw InvalidInputError("mesh has " + std::to_string(n) + " vertices but " + std::to_string(mesh.colors.size()) +
                            " colours");
  const bool weighted = !mesh.weights.empty();
  if (weighted && mesh.weights.size() != n)
    throw InvalidInputError("mesh has " + std::to_string(n) + " vertices but " + std::to_string(mesh.weights.size()) +
                            " weights");
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t v : mesh.triangles[t])
      if (v >= n)
        throw InvalidInputError("mesh triangle " + std::to_string(t) + " names vertex " + std::to_string(v) +
                                " of " + std::to_string(n));

  DisjointSets sets(n);
  for (const auto& t : mesh.triangles) {
    sets.join(t[0], t[1]);
    sets.join(t[0], t[2]);
  }
  // Triangles per piece, counted at the piece's root; a piece with a vertex of keep_weight or
  // more counts as large.
  std::vector<std::uint32_t> size(n, 0);
  for (const auto& t : mesh.triangles)
    ++size[sets.find(t[0])];
  if (weighted && keep_weight > 0.f)
    for (std::size_t v = 0; v < n; ++v)
      if (mesh.weights[v] >= keep_weight) {
        std::uint32_t& s = size[sets.find(static_cast<std::uint32_t>(v))];
        s = s > 0 ? std::max<std::uint32_t>(s, static_cast<std::uint32_t>(min_triangles)) : 0;
      }

  ComponentFilterStats stats;
  for (std::size_t v = 0; v < n; ++v)
    if (size[v] > 0) {
      ++stats.components;
      stats.components_removed += size[v] < min_triangles;
    }
  if (stats.components_removed == 0)
    return stats;

  // Keep the vertices of the large pieces (isolated vertices are dropped too), renumbered in order.
  constexpr std::uint32_t kDropped = ~std::uint32_t(0);
  std::vector<std::uint32_t> index(n, kDropped);
  std::uint32_t kept = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (size[sets.find(static_cast<std::uint32_t>(v))] >= min_triangles) {
      index[v] = kept;
      mesh.vertices[kept] = mesh.vertices[v];
      mesh.colors[kept] = mesh.colors[v];
      if (weighted)
        mesh.weights[kept] = mesh.weights[v];
      ++kept;
    }
  stats.vertices_removed = n - kept;
  mesh.vertices.resize(kept);
  mesh.colors.resize(kept);
  if (weighted)
    mesh.weights.resize(kept);

  std::size_t out = 0;
  for (const auto& t : mesh.triangles)
    if (index[t[0]] != kDropped)
      mesh.triangles[out++] = {index[t[0]], index[t[1]], index[t[2]]};
  stats.triangles_removed = mesh.triangles.size() - out;
  mesh.triangles.resize(out);
  return stats;
}

} // namespace msf
