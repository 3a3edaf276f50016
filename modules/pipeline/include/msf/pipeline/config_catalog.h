// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/range_image/ip_basic.h>
#include <msf/reconstruction/lambda_study.h>
#include <msf/synthetic/synthetic_config.h>

#include <string>
#include <vector>

namespace msf {

/// Calls visit(config) with the default Config of each section of the project's configuration
/// files, in the order config/synthetic.yaml holds them: the generator's, the pipeline's (in
/// PipelineConfig::print's order), then those of the tools beside it.
template <class Visit>
void forEachConfigSection(Visit&& visit) {
  visit(synthetic::SyntheticConfig{});
  const PipelineConfig pipeline;
  PipelineConfig::forEachSection(pipeline, visit);
  visit(IpBasicConfig{});
  visit(LambdaStudy::Config{});
}

/// The names of those sections, in that order.
std::vector<std::string> configSectionNames();

/// The config file at `path`, checked whole: every section is one of the project's (a misspelt
/// section would leave its stage at its defaults) and is read into its Config (unknown keys,
/// types, ranges, validate()), so that a mistake anywhere in the file is an error whichever
/// tool reads it. Throws IOError or ConfigError naming the file, the line and the key.
ConfigFile openConfigFile(const std::string& path);
/// The same for text in memory; `name` stands for the path in messages.
ConfigFile openConfigText(const std::string& text, const std::string& name);

/// Section Config::kSection of the config file at `path` into `config`, the file checked whole:
/// what a tool with one section does with -config.
template <class Config>
void readConfigSection(const std::string& path, Config& config) {
  openConfigFile(path).read(config);
}

/// -config of a tool that runs one stage on a rig: section Config::kSection of the file at `path`
/// into `stage` and section `rig` into `rig` (adaptToRig), the file checked whole.
template <class Config>
void readStageAndRig(const std::string& path, Config& stage, RigAdaptationConfig& rig) {
  const ConfigFile file = openConfigFile(path);
  file.read(stage);
  file.read(rig);
}

} // namespace msf
