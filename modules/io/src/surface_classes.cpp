#include <msf/common/exceptions.h>
#include <msf/io/surface_classes.h>

#include <charconv>
#include <fstream>
#include <sstream>

namespace msf {

namespace {

constexpr std::size_t kMaxVertices = std::size_t{1} << 32;

bool parseCount(const std::string& token, std::size_t& value) {
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

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
  std::ifstream in(path);
  if (!in)
    throw IOError("cannot open surface classes '" + path + "'");
  SurfaceClasses classes;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#')
      continue;
    std::istringstream tokens(line);
    std::string first_token, count_token, name, extra;
    std::size_t first = 0, count = 0;
    if (!(tokens >> first_token >> count_token >> name) || (tokens >> extra) || !parseCount(first_token, first) ||
        !parseCount(count_token, count) || count == 0)
      throw IOError("surface classes '" + path + "' line " + std::to_string(number) +
                    ": expected 'first_vertex vertex_count class' (two whole numbers, the count > 0), got '" + line +
                    "'");
    if (first != classes.vertex_class.size())
      throw IOError("surface classes '" + path + "' line " + std::to_string(number) + ": the run begins at vertex " +
                    std::to_string(first) + ", the last ended at " + std::to_string(classes.vertex_class.size()));
    // A mesh indexes its vertices with 32 bits: a longer run is a garbled file, not memory to take.
    const std::size_t limit = expected_vertices > 0 ? expected_vertices : kMaxVertices;
    if (count > limit - first)
      throw IOError("surface classes '" + path + "' line " + std::to_string(number) + ": the run of " +
                    std::to_string(count) + " vertices from " + std::to_string(first) + " goes past " +
                    (expected_vertices > 0 ? "the mesh's " + std::to_string(expected_vertices) + " vertices"
                                           : std::string("2^32 vertices")));
    std::size_t index = 0;
    while (index < classes.names.size() && classes.names[index] != name)
      ++index;
    if (index == classes.names.size()) {
      if (index == 256)
        throw IOError("surface classes '" + path + "' line " + std::to_string(number) + ": more than 256 classes");
      classes.names.push_back(name);
    }
    classes.vertex_class.insert(classes.vertex_class.end(), count, static_cast<std::uint8_t>(index));
  }
  if (expected_vertices > 0 && classes.vertex_class.size() != expected_vertices)
    throw IOError("surface classes '" + path + "' cover " + std::to_string(classes.vertex_class.size()) +
                  " vertices, the mesh has " + std::to_string(expected_vertices));
  return classes;
}

} // namespace msf
