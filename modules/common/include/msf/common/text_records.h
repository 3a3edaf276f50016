// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/exceptions.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace msf {

/// Parses the whole of `token` as a number (std::from_chars: no locale, no sign '+', no
/// spaces); false, `value` unspecified, when any of it is not the number or it is out of range.
template <typename T> bool parseNumber(const std::string& token, T& value) {
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

/// Calls record(line_number, fields, line) for each line of the text file at `path` that is
/// neither blank nor a comment (# first), its fields split at white space. Throws IOError
/// "cannot open <what> '<path>'" when the file cannot be read; what `record` throws passes.
template <typename Record> void forEachTextRecord(const std::string& path, const std::string& what, Record record) {
  std::ifstream in(path);
  if (!in)
    throw IOError("cannot open " + what + " '" + path + "'");
  std::string line;
  std::vector<std::string> fields;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    std::istringstream tokens(line);
    fields.clear();
    for (std::string token; tokens >> token;)
      fields.push_back(token);
    record(number, fields, line);
  }
}

} // namespace msf
