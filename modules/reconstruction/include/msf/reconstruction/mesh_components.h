// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/marching_cubes.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msf {

/// What removeSmallComponents removed.
struct ComponentFilterStats {
  std::size_t components = 0;         ///< connected pieces before the filter
  std::size_t components_removed = 0; ///< of those, the ones removed
  std::size_t triangles_removed = 0;
  std::size_t vertices_removed = 0;
};

/// The connected piece of each vertex of `mesh` (triangles joined through shared vertices),
/// named by the piece's smallest vertex index; a vertex no triangle uses is a piece of its own.
/// Throws InvalidInputError when a triangle names a vertex the mesh does not have.
std::vector<std::uint32_t> componentLabels(const TriangleMesh& mesh);

/// Removes the connected pieces of `mesh` (triangles joined through shared vertices) that have
/// fewer than `min_triangles` triangles, with the vertices only they use. Such specks come
/// from depth that no other frame or sensor confirms, above all SGBM's matches in the sky, but
/// so do fragments of surfaces seen at grazing angles, such as the far road, which
/// `keep_weight` holds when the LiDAR saw them.
/// With `keep_weight` > 0 and the mesh's per-vertex weights, a small piece with a vertex of at
/// least that weight is kept: it is known precisely (a pole or a sign the LiDAR saw), whatever
/// its size, unless it is closed and fits in a box of `min_extent` metres a side: a bubble of a
/// voxel or two whose sign the frames flipped against their neighbours', smaller than anything a
/// sensor resolves there; an open fragment of a surface is kept. The kept vertices and triangles
/// stay in their order. Throws InvalidInputError when a triangle names a vertex the mesh does not
/// have, or when colors (or weights, when there are any) and vertices differ in number.
ComponentFilterStats removeSmallComponents(TriangleMesh& mesh, std::size_t min_triangles, float keep_weight = 0.f,
                                           float min_extent = 0.f);

} // namespace msf
