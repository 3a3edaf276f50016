// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>

/// Reading YAML files a user writes (configuration, rig) with yaml-cpp: the file's one
/// document, errors that name the file, line and column, and scalars typed as PyYAML types
/// them, so that the project, PyYAML and ROS parameter files read each other's files.
namespace msf {

/// A YAML file larger than this is refused before it is parsed (ours are a few KB).
inline constexpr std::size_t kMaxYamlFileBytes = std::size_t(16) << 20;

/// The one document of the YAML file at `path`; a Null node when it holds none (empty, or
/// comments only). OpenCV's "%YAML:1.0" first line, which standard YAML rejects, is read
/// as a comment, so that files written for cv::FileStorage still read. `what` names the
/// file's role in messages ("config", "rig"). Throws IOError naming the file (and the line
/// and column where the parser stopped) when it is missing, not a regular file, larger than
/// kMaxYamlFileBytes, holds a NUL byte, is not valid YAML, nests deeper than yaml-cpp's
/// depth guard (checked before the parser recurses further), or holds more than one document.
YAML::Node loadYamlFile(const std::string& path, const std::string& what);

/// The same for text in memory; `name` stands for the path in messages.
YAML::Node parseYamlText(std::string text, const std::string& name, const std::string& what);

/// "line L" (1-based) of a node read from a file; "" for a node made in code.
std::string yamlLine(const YAML::Node& node);

/// "<what> '<path>' line L: " (without the line for a node made in code): the start of a
/// message about `node`.
std::string yamlWhere(const std::string& what, const std::string& path, const YAML::Node& node);

/// A key written twice in one map: yaml-cpp keeps both, and a lookup sees the first only.
struct RepeatedYamlKey {
  std::string key;
  int first_line = 0, second_line = 0; ///< 1-based
};
/// The first key of the map `node` that appears twice, if any (scalar keys only).
std::optional<RepeatedYamlKey> findRepeatedKey(const YAML::Node& node);

/// A plain (unquoted) scalar that YAML reads as a number: 5, -2.5, 1.0e-05, 1e-5, .5, .inf,
/// -.inf, .nan. nullopt for a quoted scalar, a word, or a number beyond double's range.
std::optional<double> yamlReal(const YAML::Node& node);

/// A plain scalar of decimal digits with an optional sign (no leading zero: YAML 1.1 reads
/// 010 as octal), within long long; nullopt otherwise.
std::optional<long long> yamlInteger(const YAML::Node& node);

/// A plain scalar that PyYAML reads as a boolean: true, false, yes, no, on, off (lower case,
/// capitalised or upper case); nullopt otherwise.
std::optional<bool> yamlBool(const YAML::Node& node);

/// The scalar's text for a message: quoted when YAML does not read it as a number or a
/// boolean, shortened (with its length) when long.
std::string yamlQuoted(const YAML::Node& node);

} // namespace msf
