// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace msf {

/// What each vertex of a true surface mesh is (msf_synth's gt/scene_classes.txt beside
/// gt/scene.ply): the class names, and per vertex the index of its name. The mesh evaluation
/// splits its accuracy and completeness by them (MeshAccuracy::by_class).
struct SurfaceClasses {
  std::vector<std::string> names;
  std::vector<std::uint8_t> vertex_class; ///< one per vertex of the mesh, < names.size()
};

/// The file: comment lines (#), then one line per run of vertices of one class, in vertex
/// order from 0: `first_vertex vertex_count class_name`. Throws InvalidInputError when a
/// vertex's class is not < names.size() or there are more than 256 names.
std::string formatSurfaceClasses(const SurfaceClasses& classes);
/// Throws IOError naming the file (and the line) when it cannot be read, a line is not
/// `first count name`, a run does not begin where the last ended, a run goes past
/// expected_vertices (past 2^32 when it is 0, before anything is allocated), there are more
/// than 256 names, or (expected_vertices > 0) the runs do not cover exactly that many vertices.
SurfaceClasses readSurfaceClasses(const std::string& path, std::size_t expected_vertices = 0);

} // namespace msf
