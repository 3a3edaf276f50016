// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/persistence.hpp>

#include <string>
#include <vector>

namespace msf {

/// A YAML configuration file (OpenCV FileStorage), one section per stage:
///   interpolation: { short_gap_px: 4, max_gap_px: 32 }
/// Each stage's Config struct has defaults in code and a `read(const cv::FileNode&)`
/// that overrides only the keys present (see readKey).
class ConfigFile {
public:
  ConfigFile() = default;
  /// Throws IOError if the file is missing or is not valid YAML, and ConfigError naming a
  /// section or key that appears twice in the same map.
  explicit ConfigFile(const std::string& path);

  /// The named section, or an empty node when the file or the section is absent.
  cv::FileNode section(const std::string& name) const;
  /// Throws ConfigError naming the first key, in a section asked for with section(), that
  /// no readKey call has asked for (OpenCV would let a misspelt key pass unnoticed), and a
  /// section asked for that is not a map of keys. Call it after every section is read.
  void rejectUnknownKeys() const;
  const std::string& path() const { return path_; }

private:
  void rejectRepeatedKeys(const cv::FileNode& map, const std::string& prefix) const;

  std::string path_;
  cv::FileStorage storage_;
  mutable std::vector<std::string> sections_read_;
};

/// Reads section `section` of the config file at `path` into `config` (its
/// read(const cv::FileNode&)), then rejects the keys it did not read (rejectUnknownKeys):
/// what a tool with one section does with -config.
template <typename Config>
void readConfigSection(const std::string& path, const std::string& section, Config& config) {
  const ConfigFile file(path);
  config.read(file.section(section));
  file.rejectUnknownKeys();
}

/// Overrides `value` with `node[key]` when present; throws ConfigError naming the key
/// when it has the wrong type. T: int, bool, float, double, std::string, std::vector<double>
/// (a YAML sequence of numbers, [1, 2.5]).
template <typename T>
void readKey(const cv::FileNode& node, const char* key, T& value);

/// The keys of `section` that readKey calls have asked for in this process, sorted: the keys
/// the stages that read the section know (what rejectUnknownKeys lists).
std::vector<std::string> knownConfigKeys(const std::string& section);

/// A value as a stage's print() writes it, so that readKey reads back the very same value
/// and a printed configuration reproduces a run: numbers in the fewest digits that do (0.1f
/// as 0.1, not 0.100000001), real numbers with a decimal point or exponent, booleans as
/// true / false.
std::string configValue(bool value);
std::string configValue(int value);
std::string configValue(float value);
std::string configValue(double value);

} // namespace msf
