// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace msf {

/// A configuration file: plain YAML (as people and PyYAML write it, or OpenCV's "%YAML:1.0"
/// files), one map of keys per section, read with yaml-cpp:
///   interpolation: { short_gap_px: 4, max_gap_px: 32 }
/// Each stage's Config declares its keys once (config_keys.h); read() overrides only the keys
/// present. Every error names the file, the line and the key.
class ConfigFile {
public:
  /// No file: every section is absent, read() keeps the defaults.
  ConfigFile() = default;
  /// Throws IOError when the file cannot be read, is not valid YAML (loadYamlFile), is empty
  /// or is not a map of sections, and ConfigError naming a section or key written twice or a
  /// section that is not a map of keys.
  explicit ConfigFile(const std::string& path);
  /// The same for text in memory; `name` stands for the path in messages.
  static ConfigFile fromText(const std::string& text, const std::string& name);

  const std::string& path() const { return path_; }
  /// The sections the file holds, in its order.
  std::vector<std::string> sections() const;
  /// Throws ConfigError naming the first section of the file that is not in `known` (a
  /// misspelt section would otherwise leave its stage at its defaults).
  void requireKnownSections(const std::vector<std::string>& known) const;

  /// Overrides the keys of `config` that its section (Config::kSection) holds, then validates
  /// it. Throws ConfigError with the file and line: a key the Config does not declare (listing
  /// those it does), a value of the wrong type or out of its range, a failed validate().
  template <class Config>
  void read(Config& config) const;
  /// The section's Config: the defaults overridden by the file.
  template <class Config>
  Config get() const {
    Config config;
    read(config);
    return config;
  }

  /// `error`, from a validate() after the file was read, as a ConfigError that names the file
  /// and the line of the first "section.key" of the file that its message names.
  [[noreturn]] void rethrowInFile(const ConfigError& error) const;

private:
  friend class KeyReader;
  void checkStructure() const;

  std::string path_;
  YAML::Node root_;
};

/// Reads one section of a ConfigFile: ConfigFile::read passes it to the Config's keys().
class KeyReader {
public:
  KeyReader(const ConfigFile& file, const char* section);

  void operator()(const char* key, bool& value, const char* meaning);
  void operator()(const char* key, int& value, const Range& range, const char* meaning);
  void operator()(const char* key, unsigned& value, const Range& range, const char* meaning);
  void operator()(const char* key, float& value, const Range& range, const char* meaning);
  void operator()(const char* key, double& value, const Range& range, const char* meaning);
  void operator()(const char* key, std::vector<double>& value, const Range& range, const char* meaning);
  template <std::size_t N>
  void operator()(const char* key, std::string& value, const char* const (&words)[N], const char*) {
    if (const std::optional<std::size_t> index = word(key, words, N))
      value = words[*index];
  }
  template <class E, std::size_t N>
  void operator()(const char* key, E& value, const Choice<E> (&choices)[N], const char*) {
    const char* words[N];
    for (std::size_t i = 0; i < N; ++i)
      words[i] = choices[i].word;
    if (const std::optional<std::size_t> index = word(key, words, N))
      value = choices[*index].value;
  }
  /// A key that was removed: refused with `why` when the section holds it.
  void removed(const char* key, const char* why);
  /// Throws ConfigError for the first key of the section that no call above named.
  void finish() const;

private:
  /// The value of `key` in the section, an invalid node when absent; records the key.
  YAML::Node find(const char* key);
  std::optional<std::size_t> word(const char* key, const char* const* words, std::size_t n);
  long long whole(const char* key, const YAML::Node& value, Range range, double lowest, double highest);
  double real(const char* key, const YAML::Node& value, const Range& range, double largest);
  [[noreturn]] void fail(const YAML::Node& where, const char* key, const std::string& why) const;

  const ConfigFile& file_;
  std::string section_;
  YAML::Node node_;
  std::vector<std::string> declared_;
};

template <class Config>
void ConfigFile::read(Config& config) const {
  KeyReader reader(*this, Config::kSection);
  config.keys(reader);
  reader.finish();
  try {
    config.validate();
  } catch (const ConfigError& e) {
    rethrowInFile(e);
  }
}

} // namespace msf
