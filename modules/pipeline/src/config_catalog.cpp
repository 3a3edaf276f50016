// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/config_catalog.h>

namespace msf {

namespace {

ConfigFile checkedWhole(ConfigFile file) {
  file.requireKnownSections(configSectionNames());
  forEachConfigSection([&](const auto& defaults) {
    auto config = defaults;
    file.read(config);
  });
  return file;
}

} // namespace

std::vector<std::string> configSectionNames() {
  std::vector<std::string> names;
  forEachConfigSection([&](const auto& config) { names.emplace_back(config.kSection); });
  return names;
}

ConfigFile openConfigFile(const std::string& path) { return checkedWhole(ConfigFile(path)); }

ConfigFile openConfigText(const std::string& text, const std::string& name) {
  return checkedWhole(ConfigFile::fromText(text, name));
}

} // namespace msf
