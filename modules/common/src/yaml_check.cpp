// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/yaml_check.h>

#include <fstream>
#include <sstream>

namespace msf {

void requireYamlTopLevelAtColumnZero(const std::string& path, const std::string& what) {
  // The top level's first line is among the file's first 64 KB, or the file is no YAML of ours.
  std::string head(1 << 16, '\0');
  std::ifstream file(path, std::ios::binary);
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  std::istringstream in(head);
  std::string line;
  for (std::size_t line_no = 1; std::getline(in, line); ++line_no) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#' || line[0] == '%')
      continue; // blank, a comment, a directive (%YAML:1.0)
    auto refuse = [&](const std::string& why) {
      throw IOError(what + " '" + path + "' is not valid YAML: line " + std::to_string(line_no) + ": " + why +
                    " (the top level must start at column 0 of its own line: OpenCV's parser can loop forever "
                    "on an indented one)");
    };
    if (line.rfind("---", 0) == 0) {
      if (line.find_first_not_of(" \t", 3) == std::string::npos)
        continue;
      refuse("content on the '---' line");
    }
    if (first > 0)
      refuse("the top level is indented by " + std::to_string(first) + " character" + (first > 1 ? "s" : ""));
    return;
  }
}

} // namespace msf
