// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/text_records.h>
#include <msf/io/surface_classes.h>

namespace msf {

namespace {

constexpr std::size_t kMaxVertices = std::size_t{1} << 32;

} // namespace

std::string formatSurfaceClasses(const SurfaceClasses& classes) {
  if (classes.names.size() > 256)
    throw InvalidInputError("surface classes: " + std::to_string(classes.names.size()) + " names, at most 256");
  std::string text = "# the class of each vertex of scene.ply, in runs: first_vertex vertex_count class\n";
  const std::size_t n = classes.vertex_class.size();
  for (std::size_t first = 0; first < n;) {
    const std::uint8_t c = classes.vertex_class[first];
    if (c >= classes.names.size())
      throw InvalidInputError("surface classes: vertex " + std::to_string(first) + " has class " + std::to_string(c) +
                              " of " + std::to_string(classes.names.size()) + " names");
    std::size_t end = first + 1;
    while (end < n && classes.vertex_class[end] == c)
      ++end;
    text += std::to_string(first) + " " + std::to_string(end - first) + " " + classes.names[c] + "\n";
    first = end;
  }
  return text;
}

SurfaceClasses readSurfaceClasses(const std::string& path, std::size_t expected_vertices) {
  SurfaceClasses classes;
  forEachTextRecord(path, "surface classes", [&](int number, const std::vector<std::string>& fields,
                                                 const std::string& line) {
    const std::string at = "surface classes '" + path + "' line " + std::to_string(number);
    std::size_t first = 0, count = 0;
    if (fields.size() != 3 || !parseNumber(fields[0], first) || !parseNumber(fields[1], count) || count == 0)
      throw IOError(at + ": expected 'first_vertex vertex_count class' (two whole numbers, the count > 0), got '" +
                    line + "'");
    if (first != classes.vertex_class.size())
      throw IOError(at + ": the run begins at vertex " + std::to_string(first) + ", the last ended at " +
                    std::to_string(classes.vertex_class.size()));
    // A mesh indexes its vertices with 32 bits: a longer run is a garbled file, not memory to take.
    const std::size_t limit = expected_vertices > 0 ? expected_vertices : kMaxVertices;
    if (count > limit - first)
      throw IOError(at + ": the run of " + std::to_string(count) + " vertices from " + std::to_string(first) +
                    " goes past " +
                    (expected_vertices > 0 ? "the mesh's " + std::to_string(expected_vertices) + " vertices"
                                           : std::string("2^32 vertices")));
    const std::string& name = fields[2];
    std::size_t index = 0;
    while (index < classes.names.size() && classes.names[index] != name)
      ++index;
    if (index == classes.names.size()) {
      if (index == 256)
        throw IOError(at + ": more than 256 classes");
      classes.names.push_back(name);
    }
    classes.vertex_class.insert(classes.vertex_class.end(), count, static_cast<std::uint8_t>(index));
  });
  if (expected_vertices > 0 && classes.vertex_class.size() != expected_vertices)
    throw IOError("surface classes '" + path + "' cover " + std::to_string(classes.vertex_class.size()) +
                  " vertices, the mesh has " + std::to_string(expected_vertices));
  return classes;
}

} // namespace msf
