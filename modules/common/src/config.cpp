#include <msf/common/atomic_file.h>
#include <opencv2/core.hpp>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>

#include <algorithm>
#include <vector>

namespace msf {

ConfigFile::ConfigFile(const std::string& path) : path_(path) {
  requireFile(path, "config");
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

cv::FileNode ConfigFile::section(const std::string& name) const {
  if (!storage_.isOpened())
    return cv::FileNode();
  return storage_[name];
}

namespace {
std::string keyName(const cv::FileNode& node, const char* key) {
  const std::string section = node.name();
  return section.empty() ? std::string(key) : section + "." + key;
}
} // namespace

template <typename T>
void readKey(const cv::FileNode& node, const char* key, T& value) {
  if (node.empty() || !node.isMap())
    return;
  const cv::FileNode item = node[key];
  if (item.empty() || item.isNone())
    return;
  if constexpr (std::is_same_v<T, std::string>) {
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

} // namespace msf
