// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/marching_cubes.h>

#include <cstddef>

namespace msf {

/// What removeSmallComponents removed.
struct ComponentFilterStats {
  std::size_t components = 0;         ///< connected pieces before the filter
  std::size_t components_removed = 0; ///< of those, the ones removed
  std::size_t triangles_removed = 0;
  std::size_t vertices_removed = 0;
};

/// Removes the connected pieces of `mesh` (triangles joined through shared vertices) that have
/// fewer than `min_triangles` triangles, with the vertices only they use. Such specks come
/// from depth that no other frame or sensor confirms, above all SGBM's matches in the sky, but
/// so do fragments of surfaces seen at grazing angles, such as the far road, which
/// `keep_weight` holds when the LiDAR saw them.
/// With `keep_weight` > 0 and the mesh's per-vertex weights, a small piece with a vertex of at
/// least that weight is kept: it is known precisely (a pole or a sign the LiDAR saw), whatever
/// its size. The kept vertices and triangles stay in their order. Throws InvalidInputError when a
/// triangle names a vertex the mesh does not have, or when colors (or weights, when there are
/// any) and vertices differ in number.
ComponentFilterStats removeSmallComponents(TriangleMesh& mesh, std::size_t min_triangles, float keep_weight = 0.f);

} // namespace msf
