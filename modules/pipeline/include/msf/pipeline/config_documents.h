// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <string>
#include <vector>

/// The files made from the configuration keys' declarations (forEachConfigSection): the
/// configuration files the project ships and the reference of every key. `msf_config -write`
/// (make config-files) writes them; a test compares them with the files in the repository, so
/// that they cannot drift from the code.
namespace msf {

/// "kitti", "synthetic", "paper".
std::vector<std::string> shippedConfigNames();

/// config/<name>.yaml: kitti, every key of the pipeline's sections and ip_basic at its default;
/// synthetic, the same with the synthetic and lambda_study sections; paper, the keys whose value
/// PipelineConfig::paper() changes. Each section and key has its meaning (and range) as a
/// comment above it. Throws InvalidInputError for another name.
std::string shippedConfigText(const std::string& name);

/// docs/configuration.md: every key of every section in one table (section, key, default,
/// range, meaning).
std::string configurationReference();

} // namespace msf
