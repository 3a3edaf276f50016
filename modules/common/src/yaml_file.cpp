// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/yaml_file.h>

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <vector>

namespace msf {

namespace {

std::string lineAndColumn(const YAML::Mark& mark) {
  if (mark.is_null())
    return "";
  return "line " + std::to_string(mark.line + 1) + ", column " + std::to_string(mark.column + 1) + ": ";
}

/// OpenCV writes "%YAML:1.0" as its first line, a directive standard YAML does not know: it
/// is blanked, its line kept so that line numbers hold.
void blankOpenCvDirective(std::string& text) {
  if (text.rfind("%YAML:", 0) != 0)
    return;
  const std::size_t end = text.find('\n');
  text.erase(0, end == std::string::npos ? text.size() : end);
}

std::string readWholeFile(const std::string& path, const std::string& what) {
  requireFile(path, what);
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IOError(what + " '" + path + "' cannot be opened: " + std::strerror(errno), path, errno);
  std::string text;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxYamlFileBytes)
      throw IOError(what + " '" + path + "' is larger than " + std::to_string(kMaxYamlFileBytes >> 20) +
                    " MiB: not a YAML file of settings");
  }
  if (in.bad())
    throw IOError(what + " '" + path + "' cannot be read: " + std::strerror(errno));
  return text;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

/// True for a node the file wrote as a plain scalar (no quotes, no tag), or with `core_tag`.
bool plainScalar(const YAML::Node& node, const char* core_tag) {
  return node.IsScalar() && (node.Tag() == "?" || node.Tag() == std::string("tag:yaml.org,2002:") + core_tag);
}

/// YAML 1.2's number syntax (which YAML 1.1's, PyYAML's, is within but for its exponent sign
/// and leading dot): [-+]? ( . digits | digits ( . digits? )? ) ( [eE] [-+]? digits )?
bool realSyntax(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '-' || s[0] == '+')) ? 1 : 0;
  std::size_t digits = 0;
  while (i < s.size() && isDigit(s[i]))
    ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && isDigit(s[i]))
      ++i, ++digits;
  }
  if (digits == 0)
    return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '-' || s[i] == '+'))
      ++i;
    const std::size_t exponent = i;
    while (i < s.size() && isDigit(s[i]))
      ++i;
    if (i == exponent)
      return false;
  }
  return i == s.size();
}

} // namespace

YAML::Node parseYamlText(std::string text, const std::string& name, const std::string& what) {
  const std::string file = what + " '" + name + "'";
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
    throw IOError(file + " is not a text file: a NUL byte on line " +
                  std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(nul), '\n')));
  blankOpenCvDirective(text);
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::DeepRecursion& e) {
    throw IOError(file + " is not valid YAML: " + lineAndColumn(e.mark) + "nested more than " +
                  std::to_string(e.depth() - 1) + " levels deep (yaml-cpp's limit)");
  } catch (const YAML::Exception& e) {
    throw IOError(file + " is not valid YAML: " + lineAndColumn(e.mark) + e.msg);
  }
  if (documents.size() > 1)
    throw IOError(file + " holds " + std::to_string(documents.size()) +
                  " YAML documents (separated by '---'); it must hold one");
  return documents.empty() ? YAML::Node(YAML::NodeType::Null) : documents.front();
}

YAML::Node loadYamlFile(const std::string& path, const std::string& what) {
  return parseYamlText(readWholeFile(path, what), path, what);
}

std::string yamlLine(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? "" : "line " + std::to_string(mark.line + 1);
}

std::string yamlWhere(const std::string& what, const std::string& path, const YAML::Node& node) {
  const std::string line = yamlLine(node);
  return what + " '" + path + "'" + (line.empty() ? "" : " " + line) + ": ";
}

std::optional<RepeatedYamlKey> findRepeatedKey(const YAML::Node& node) {
  if (!node.IsMap())
    return std::nullopt;
  std::map<std::string, int> first_line;
  for (const auto& entry : node) {
    if (!entry.first.IsScalar())
      continue;
    const int line = entry.first.Mark().line + 1;
    const auto [it, inserted] = first_line.emplace(entry.first.Scalar(), line);
    if (!inserted)
      return RepeatedYamlKey{entry.first.Scalar(), it->second, line};
  }
  return std::nullopt;
}

std::optional<double> yamlReal(const YAML::Node& node) {
  if (!plainScalar(node, "float") && !plainScalar(node, "int"))
    return std::nullopt;
  const std::string& s = node.Scalar();
  const std::size_t sign = (!s.empty() && (s[0] == '-' || s[0] == '+')) ? 1 : 0;
  const std::string word = s.substr(sign);
  if (word == ".inf" || word == ".Inf" || word == ".INF")
    return s[0] == '-' ? -HUGE_VAL : HUGE_VAL;
  if (sign == 0 && (word == ".nan" || word == ".NaN" || word == ".NAN"))
    return std::nan("");
  const bool octal_looking = word.size() > 1 && word[0] == '0' && std::all_of(word.begin(), word.end(), isDigit);
  if (!realSyntax(s) || octal_looking) // YAML 1.1 reads 010 as octal
    return std::nullopt;
  double value = 0;
  const auto [end, error] = std::from_chars(s.data() + sign, s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size())
    return std::nullopt; // beyond double's range
  return s[0] == '-' ? -value : value;
}

std::optional<long long> yamlInteger(const YAML::Node& node) {
  if (!plainScalar(node, "int"))
    return std::nullopt;
  const std::string& s = node.Scalar();
  const std::size_t sign = (!s.empty() && (s[0] == '-' || s[0] == '+')) ? 1 : 0;
  const std::size_t digits = s.size() - sign;
  if (digits == 0 || !std::all_of(s.begin() + static_cast<std::ptrdiff_t>(sign), s.end(), isDigit) ||
      (digits > 1 && s[sign] == '0'))
    return std::nullopt;
  long long value = 0;
  const auto [end, error] = std::from_chars(s.data() + (s[0] == '+' ? 1 : 0), s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size())
    return std::nullopt; // beyond long long
  return value;
}

std::optional<bool> yamlBool(const YAML::Node& node) {
  if (!plainScalar(node, "bool"))
    return std::nullopt;
  static const char* const kTrue[] = {"true", "True", "TRUE", "yes", "Yes", "YES", "on", "On", "ON"};
  static const char* const kFalse[] = {"false", "False", "FALSE", "no", "No", "NO", "off", "Off", "OFF"};
  const std::string& s = node.Scalar();
  for (const char* word : kTrue)
    if (s == word)
      return true;
  for (const char* word : kFalse)
    if (s == word)
      return false;
  return std::nullopt;
}

namespace {
/// True for a plain scalar written as a number, in range or not.
bool numberLike(const YAML::Node& node) {
  if (!plainScalar(node, "float") && !plainScalar(node, "int"))
    return false;
  const std::string& s = node.Scalar();
  const std::string word = s.substr(!s.empty() && (s[0] == '-' || s[0] == '+') ? 1 : 0);
  return realSyntax(s) || word == ".inf" || word == ".Inf" || word == ".INF" || s == ".nan" || s == ".NaN" ||
         s == ".NAN";
}
} // namespace

std::string yamlQuoted(const YAML::Node& node) {
  if (node.IsSequence())
    return "a sequence";
  if (node.IsMap())
    return "a map";
  if (!node.IsScalar())
    return "nothing";
  constexpr std::size_t kShown = 40;
  const std::string& s = node.Scalar();
  std::string text = s.size() > kShown ? s.substr(0, kShown) + "..." : s;
  if (!numberLike(node) && !yamlBool(node))
    text = "'" + text + "'";
  return s.size() > kShown ? text + " (" + std::to_string(s.size()) + " characters)" : text;
}

} // namespace msf
