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
/// so do fragments of surfaces seen at grazing angles, such as the far road (README).
/// The kept vertices and triangles stay in their order. Throws InvalidInputError when a
/// triangle names a vertex the mesh does not have, or when colors and vertices differ in number.
ComponentFilterStats removeSmallComponents(TriangleMesh& mesh, std::size_t min_triangles);

} // namespace msf
