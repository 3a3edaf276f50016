// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/reconstruction/mesh_components.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>
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

std::vector<std::uint32_t> componentLabels(const TriangleMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
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
  std::vector<std::uint32_t> label(n);
  for (std::size_t v = 0; v < n; ++v)
    label[v] = sets.find(static_cast<std::uint32_t>(v));
  return label;
}

namespace {

/// Whether each piece (at its label) fits in a box of `extent` a side.
std::vector<char> piecesWithin(const TriangleMesh& mesh, const std::vector<std::uint32_t>& piece, float extent) {
  const std::size_t n = mesh.vertices.size();
  std::vector<char> within(n, 0);
  if (!(extent > 0.f))
    return within;
  std::vector<Eigen::Vector3f> low(n, Eigen::Vector3f::Constant(std::numeric_limits<float>::max()));
  std::vector<Eigen::Vector3f> high(n, Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest()));
  for (std::size_t v = 0; v < n; ++v) {
    low[piece[v]] = low[piece[v]].cwiseMin(mesh.vertices[v]);
    high[piece[v]] = high[piece[v]].cwiseMax(mesh.vertices[v]);
  }
  for (std::size_t v = 0; v < n; ++v)
    within[v] = piece[v] == v && (high[v] - low[v]).maxCoeff() < extent;
  return within;
}

/// Of the pieces `marked` (at their labels), unmarks those that are not closed: an edge not
/// shared by exactly two of the piece's triangles. A closed piece that small is a bubble of a
/// voxel or two of flipped sign; an open one is a fragment of a surface that holes cut off.
void unmarkOpenPieces(const TriangleMesh& mesh, const std::vector<std::uint32_t>& piece, std::vector<char>& marked) {
  std::unordered_map<std::uint64_t, int> edges; // (smaller vertex, larger) -> triangles
  for (const auto& t : mesh.triangles)
    if (marked[piece[t[0]]])
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        ++edges[static_cast<std::uint64_t>(std::min(a, b)) << 32 | std::max(a, b)];
      }
  for (const auto& [edge, triangles] : edges)
    if (triangles != 2)
      marked[piece[static_cast<std::uint32_t>(edge >> 32)]] = 0;
}

} // namespace

ComponentFilterStats removeSmallComponents(TriangleMesh& mesh, std::size_t min_triangles, float keep_weight,
                                           float min_extent) {
  const std::size_t n = mesh.vertices.size();
  if (mesh.colors.size() != n)
    throw InvalidInputError("mesh has " + std::to_string(n) + " vertices but " + std::to_string(mesh.colors.size()) +
                            " colours");
  const bool weighted = !mesh.weights.empty();
  if (weighted && mesh.weights.size() != n)
    throw InvalidInputError("mesh has " + std::to_string(n) + " vertices but " + std::to_string(mesh.weights.size()) +
                            " weights");

  const std::vector<std::uint32_t> piece = componentLabels(mesh);
  // Triangles per piece, counted at the piece's label; a piece with a vertex of keep_weight or
  // more counts as large.
  std::vector<std::uint32_t> size(n, 0);
  for (const auto& t : mesh.triangles)
    ++size[piece[t[0]]];
  if (weighted && keep_weight > 0.f) {
    std::vector<char> tiny = piecesWithin(mesh, piece, min_extent);
    unmarkOpenPieces(mesh, piece, tiny);
    for (std::size_t v = 0; v < n; ++v)
      if (mesh.weights[v] >= keep_weight && !tiny[piece[v]]) {
        std::uint32_t& s = size[piece[v]];
        s = s > 0 ? std::max<std::uint32_t>(s, static_cast<std::uint32_t>(min_triangles)) : 0;
      }
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
    if (size[piece[v]] >= min_triangles) {
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
