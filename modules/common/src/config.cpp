// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <opencv2/core.hpp>
#include <msf/common/config.h>
#include <msf/common/yaml_check.h>
#include <msf/common/exceptions.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <mutex>
#include <sstream>
#include <set>
#include <vector>

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

ConfigFile::ConfigFile(const std::string& path) : path_(path) {
  requireFile(path, "config");
  requireYamlTopLevelAtColumnZero(path, "config");
  try {
    storage_.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    throw IOError("config '" + path + "' is not valid YAML: " + e.err);
  }
  if (!storage_.isOpened())
    throw IOError("config '" + path + "' cannot be opened as YAML");
  rejectRepeatedKeys(storage_.root(), "");
}

void ConfigFile::rejectRepeatedKeys(const cv::FileNode& map, const std::string& prefix) const {
  // OpenCV keeps a repeated key and reads only its first value: a section pasted twice
  // would silently hide the edits made to its second copy.
  if (!map.isMap())
    return;
  std::vector<std::string> names;
  for (auto it = map.begin(); it != map.end(); ++it) {
    const cv::FileNode node = *it;
    const std::string name = prefix + node.name();
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw ConfigError("config '" + path_ + "': '" + name + "' appears twice (only the first would be read)");
    names.push_back(name);
    rejectRepeatedKeys(node, name + ".");
  }
}

namespace {
std::string keyName(const cv::FileNode& node, const char* key) {
  const std::string section = node.name();
  return section.empty() ? std::string(key) : section + "." + key;
}

/// Every "section.key" a readKey call has asked for in this process: the keys some stage reads.
struct KnownKeys {
  std::mutex mutex;
  std::set<std::string> names;
};
KnownKeys& knownKeys() {
  static KnownKeys keys;
  return keys;
}
} // namespace

cv::FileNode ConfigFile::section(const std::string& name) const {
  if (!storage_.isOpened())
    return cv::FileNode();
  if (std::find(sections_read_.begin(), sections_read_.end(), name) == sections_read_.end())
    sections_read_.push_back(name);
  return storage_[name];
}

std::vector<std::string> knownConfigKeys(const std::string& section) {
  KnownKeys& known = knownKeys();
  const std::lock_guard<std::mutex> lock(known.mutex);
  std::vector<std::string> keys;
  for (auto k = known.names.lower_bound(section + "."); k != known.names.end() && k->rfind(section + ".", 0) == 0; ++k)
    keys.push_back(k->substr(section.size() + 1));
  return keys;
}

void ConfigFile::rejectUnknownKeys() const {
  if (!storage_.isOpened())
    return;
  for (const std::string& name : sections_read_) {
    const cv::FileNode section = storage_[name];
    if (section.empty() || section.isNone())
      continue;
    if (!section.isMap())
      throw ConfigError("config '" + path_ + "': section '" + name + "' must hold keys (key: value), one per line");
    const std::vector<std::string> known = knownConfigKeys(name);
    for (auto it = section.begin(); it != section.end(); ++it) {
      if (std::binary_search(known.begin(), known.end(), (*it).name()))
        continue;
      std::string keys;
      for (const std::string& k : known)
        keys += (keys.empty() ? "" : ", ") + k;
      throw ConfigError("config '" + path_ + "': '" + name + "." + (*it).name() + "' is not a key of section '" +
                        name + "' (its keys: " + keys + ")");
    }
  }
}

std::string configValue(bool value) { return value ? "true" : "false"; }

std::string configValue(int value) { return std::to_string(value); }

namespace {
template <typename Real>
std::string shortestReal(Real value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".en") == std::string::npos)
    text += ".0"; // a real number stays one: 5.0, not the integer 5
  return text;
}
} // namespace

std::string configValue(float value) { return shortestReal(value); }

std::string configValue(double value) { return shortestReal(value); }

template <typename T>
void readKey(const cv::FileNode& node, const char* key, T& value) {
  if (node.empty() || !node.isMap())
    return;
  {
    KnownKeys& known = knownKeys();
    const std::lock_guard<std::mutex> lock(known.mutex);
    known.names.insert(keyName(node, key));
  }
  const cv::FileNode item = node[key];
  if (item.empty() || item.isNone())
    return;
  if constexpr (std::is_same_v<T, std::vector<double>>) {
    if (!item.isSeq())
      throw ConfigError("config key '" + keyName(node, key) + "' must be a sequence of numbers");
    std::vector<double> values;
    for (const auto& v : item) {
      if (!v.isReal() && !v.isInt())
        throw ConfigError("config key '" + keyName(node, key) + "' must be a sequence of numbers");
      values.push_back(v.real());
    }
    value = std::move(values);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!item.isString())
      throw ConfigError("config key '" + keyName(node, key) + "' must be a string");
    value = static_cast<std::string>(item);
  } else if constexpr (std::is_same_v<T, bool>) {
    if (item.isInt()) {
      value = static_cast<int>(item) != 0;
    } else if (item.isString()) {
      const std::string s = item;
      if (s == "true" || s == "on" || s == "yes") value = true;
      else if (s == "false" || s == "off" || s == "no") value = false;
      else throw ConfigError("config key '" + keyName(node, key) + "' must be true or false, not '" + s + "'");
    } else {
      throw ConfigError("config key '" + keyName(node, key) + "' must be true or false");
    }
  } else {
    if (!item.isReal() && !item.isInt())
      throw ConfigError("config key '" + keyName(node, key) + "' must be a number");
    if constexpr (std::is_integral_v<T>) {
      const double v = item.real();
      if (item.isReal() && v != static_cast<double>(static_cast<long long>(v)))
        throw ConfigError("config key '" + keyName(node, key) + "' must be a whole number");
      value = static_cast<T>(item.isInt() ? static_cast<int>(item) : v);
    } else {
      value = static_cast<T>(item.isInt() ? static_cast<double>(static_cast<int>(item)) : item.real());
    }
  }
}

template void readKey<int>(const cv::FileNode&, const char*, int&);
template void readKey<bool>(const cv::FileNode&, const char*, bool&);
template void readKey<float>(const cv::FileNode&, const char*, float&);
template void readKey<double>(const cv::FileNode&, const char*, double&);
template void readKey<std::string>(const cv::FileNode&, const char*, std::string&);
template void readKey<std::vector<double>>(const cv::FileNode&, const char*, std::vector<double>&);

} // namespace msf
