// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/yaml_file.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <climits>
#include <cmath>
#include <utility>

namespace msf {

namespace {

const char* kindOf(const YAML::Node& node) {
  return node.IsSequence() ? "a sequence" : node.IsMap() ? "a map" : node.IsScalar() ? "a single value" : "empty";
}

/// The key node and the value of `key` in the map `map`, invalid nodes when absent (a lookup
/// that cannot insert).
std::pair<YAML::Node, YAML::Node> entryOf(const YAML::Node& map, const std::string& key) {
  if (map.IsMap())
    for (const auto& entry : map)
      if (entry.first.IsScalar() && entry.first.Scalar() == key)
        return {entry.first, entry.second};
  return {YAML::Node(YAML::NodeType::Undefined), YAML::Node(YAML::NodeType::Undefined)};
}

/// True when `text` names `name` as a whole word ("stereo.p1" is not "stereo.p").
bool names(const std::string& text, const std::string& name) {
  for (std::size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    const std::size_t end = at + name.size();
    if (end == text.size() || !(std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_'))
      return true;
  }
  return false;
}

} // namespace

ConfigFile::ConfigFile(const std::string& path) : path_(path), root_(loadYamlFile(path, "config")) {
  checkStructure();
}

ConfigFile ConfigFile::fromText(const std::string& text, const std::string& name) {
  ConfigFile file;
  file.path_ = name;
  file.root_ = parseYamlText(text, name, "config");
  file.checkStructure();
  return file;
}

void ConfigFile::checkStructure() const {
  const std::string file = "config '" + path_ + "'";
  if (root_.IsNull())
    throw IOError(file + " is empty: a config file holds sections of keys (a line 'stereo:', then "
                         "'  block_size_px: 5' below it)");
  if (!root_.IsMap())
    throw IOError(yamlWhere("config", path_, root_) + "a config file is a map of sections (a line 'stereo:', "
                  "then its keys below it), not " + kindOf(root_));
  if (const auto repeated = findRepeatedKey(root_))
    throw ConfigError(file + " line " + std::to_string(repeated->second_line) + ": section '" + repeated->key +
                      "' appears twice (lines " + std::to_string(repeated->first_line) + " and " +
                      std::to_string(repeated->second_line) + ")");
  for (const auto& section : root_) {
    if (!section.first.IsScalar())
      throw ConfigError(yamlWhere("config", path_, section.first) + "a section's name must be a word, not " +
                        kindOf(section.first));
    const std::string name = section.first.Scalar();
    if (!section.second.IsMap() && !section.second.IsNull())
      throw ConfigError(yamlWhere("config", path_, section.second) + "section '" + name +
                        "' must hold keys (key: value), one per line, not " + kindOf(section.second));
    if (const auto repeated = findRepeatedKey(section.second))
      throw ConfigError(file + " line " + std::to_string(repeated->second_line) + ": '" + name + "." + repeated->key +
                        "' appears twice (lines " + std::to_string(repeated->first_line) + " and " +
                        std::to_string(repeated->second_line) + ")");
  }
}

std::vector<std::string> ConfigFile::sections() const {
  std::vector<std::string> names;
  if (root_.IsMap())
    for (const auto& section : root_)
      names.push_back(section.first.Scalar());
  return names;
}

void ConfigFile::requireKnownSections(const std::vector<std::string>& known) const {
  if (!root_.IsMap())
    return;
  for (const auto& section : root_) {
    const std::string& name = section.first.Scalar();
    if (std::find(known.begin(), known.end(), name) != known.end())
      continue;
    std::string list;
    for (const std::string& k : known)
      list += (list.empty() ? "" : ", ") + k;
    throw ConfigError(yamlWhere("config", path_, section.first) + "'" + name +
                      "' is not a section of the configuration (its sections: " + list + ")");
  }
}

void ConfigFile::rethrowInFile(const ConfigError& error) const {
  const std::string message = error.what();
  if (root_.IsMap())
    for (const auto& section : root_)
      if (section.second.IsMap())
        for (const auto& key : section.second)
          if (key.first.IsScalar() && names(message, section.first.Scalar() + "." + key.first.Scalar()))
            throw ConfigError(yamlWhere("config", path_, key.first) + message);
  throw ConfigError("config '" + path_ + "': " + message);
}

KeyReader::KeyReader(const ConfigFile& file, const char* section)
    : file_(file), section_(section), node_(entryOf(file.root_, section).second) {}

YAML::Node KeyReader::find(const char* key) {
  declared_.emplace_back(key);
  const auto [name, value] = entryOf(node_, key);
  if (value.IsDefined() && value.IsNull()) // an empty value is marked where the next line starts: name the key's
    fail(name, key, "has no value (write one, or delete the line to keep the default)");
  return value;
}

void KeyReader::fail(const YAML::Node& where, const char* key, const std::string& why) const {
  throw ConfigError(yamlWhere("config", file_.path_, where) + section_ + "." + key + " " + why);
}

void KeyReader::operator()(const char* key, bool& value, const char*) {
  const YAML::Node node = find(key);
  if (!node.IsDefined())
    return;
  if (const std::optional<bool> b = yamlBool(node)) {
    value = *b;
    return;
  }
  const std::optional<long long> number = yamlInteger(node);
  if (!number || (*number != 0 && *number != 1))
    fail(node, key, "must be true or false, not " + yamlQuoted(node));
  value = *number == 1;
}

long long KeyReader::whole(const char* key, const YAML::Node& node, Range range, double lowest, double highest) {
  // The type's own bounds join the declared range, so that 4294967297 is out of range, not wrapped.
  if (range.min < lowest)
    range = {lowest, range.max, false, range.max_open};
  if (range.max > highest)
    range = {range.min, highest, range.min_open, false};
  std::optional<long long> value = yamlInteger(node);
  if (!value)
    if (const std::optional<double> real = yamlReal(node); real && std::isfinite(*real) &&
                                                             *real == std::trunc(*real) && std::fabs(*real) < 1e18)
      value = static_cast<long long>(*real); // 4.0, 1e3: whole numbers written as reals
  if (!value || !range.contains(static_cast<double>(*value)))
    fail(node, key, "must be a whole number in " + range.text() + ", not " + yamlQuoted(node));
  return *value;
}

void KeyReader::operator()(const char* key, int& value, const Range& range, const char*) {
  if (const YAML::Node node = find(key); node.IsDefined())
    value = static_cast<int>(whole(key, node, range, INT_MIN, INT_MAX));
}

void KeyReader::operator()(const char* key, unsigned& value, const Range& range, const char*) {
  if (const YAML::Node node = find(key); node.IsDefined())
    value = static_cast<unsigned>(whole(key, node, range, 0, UINT_MAX));
}

double KeyReader::real(const char* key, const YAML::Node& node, const Range& range, double largest) {
  const std::optional<double> value = yamlReal(node);
  if (value && std::isfinite(*value) && std::fabs(*value) <= largest && range.contains(*value))
    return *value;
  const std::string bounds = range.text();
  const bool interval = std::isfinite(range.min) && std::isfinite(range.max);
  fail(node, key, "must be a finite number" + (bounds.empty() ? "" : (interval ? " in " : " ") + bounds) +
                      ", not " + yamlQuoted(node));
}

void KeyReader::operator()(const char* key, float& value, const Range& range, const char*) {
  if (const YAML::Node node = find(key); node.IsDefined())
    value = static_cast<float>(real(key, node, range, FLT_MAX));
}

void KeyReader::operator()(const char* key, double& value, const Range& range, const char*) {
  if (const YAML::Node node = find(key); node.IsDefined())
    value = real(key, node, range, DBL_MAX);
}

void KeyReader::operator()(const char* key, std::vector<double>& value, const Range& range, const char*) {
  const YAML::Node node = find(key);
  if (!node.IsDefined())
    return;
  if (!node.IsSequence())
    fail(node, key, "must be a sequence of numbers ([1, 2.5]), not " + yamlQuoted(node));
  std::vector<double> values;
  for (const YAML::Node& item : node)
    values.push_back(real(key, item, range, DBL_MAX));
  value = std::move(values);
}

std::optional<std::size_t> KeyReader::word(const char* key, const char* const* words, std::size_t n) {
  const YAML::Node node = find(key);
  if (!node.IsDefined())
    return std::nullopt;
  if (node.IsScalar())
    for (std::size_t i = 0; i < n; ++i)
      if (node.Scalar() == words[i])
        return i;
  fail(node, key, "must be " + wordList(words, n) + ", not " + yamlQuoted(node));
}

void KeyReader::removed(const char* key, const char* why) {
  const YAML::Node node = find(key);
  if (node.IsDefined())
    fail(node, key, std::string("was removed: ") + why);
}

void KeyReader::finish() const {
  if (!node_.IsMap())
    return;
  for (const auto& entry : node_) {
    const std::string name = entry.first.IsScalar() ? entry.first.Scalar() : "";
    if (std::find(declared_.begin(), declared_.end(), name) != declared_.end())
      continue;
    std::string keys;
    for (const std::string& k : declared_)
      keys += (keys.empty() ? "" : ", ") + k;
    throw ConfigError(yamlWhere("config", file_.path_, entry.first) + "'" + section_ + "." +
                      (name.empty() ? std::string(kindOf(entry.first)) : name) + "' is not a key of section '" +
                      section_ + "' (its keys: " + keys + ")");
  }
}

} // namespace msf
