// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The configuration of every stage (msf::PipelineConfig, one YAML section per stage, as in
// config/kitti.yaml) as msfusion.Config; each stage object takes its own section from it.
#include "bindings.h"

#include <msf/pipeline/config_catalog.h>
#include <msf/pipeline/pipeline_config.h>

#include <sstream>
#include <string>

namespace msf::python {
namespace {

std::string yamlOf(const PipelineConfig& config) {
  std::ostringstream text;
  config.print(text);
  return text.str();
}

/// The defaults overridden by the sections of `text`, checked as a file is; `name` stands for
/// the text in messages.
PipelineConfig fromYaml(const std::string& text, const std::string& name) {
  PipelineConfig config;
  config.read(openConfigText(text, name));
  return config;
}

} // namespace

void bindConfig(py::module_& m) {
  py::class_<PipelineConfig> config(m, "Config",
                                    "Every stage's settings, one YAML section per stage (config/kitti.yaml lists "
                                    "every key). Config() is the defaults; msfusion.load_config reads a file and "
                                    "overrides keys.");
  copyable(config)
      .def(py::init<>())
      .def_static("load", [](const std::filesystem::path& path) { return PipelineConfig::load(path.string()); },
                  py::arg("path"), py::call_guard<py::gil_scoped_release>(),
                  "The defaults overridden by the sections of a YAML file. Raises IOError for a missing file, "
                  "ConfigError naming a bad or unknown key.")
      .def_static("paper", &PipelineConfig::paper,
                  "The paper as published (Ali, Rajput et al. 2019), without the project's additions.")
      .def_static("from_yaml", &fromYaml, py::arg("text"), py::arg("name") = "yaml text",
                  "The defaults overridden by the sections of YAML text, checked as Config.load checks a file; "
                  "name stands for the text in a ConfigError's message.")
      .def("yaml", &yamlOf,
           "Every key of every section as a YAML file that Config.load reads back to the same configuration.")
      .def("__eq__", [](const PipelineConfig& a, const PipelineConfig& b) { return yamlOf(a) == yamlOf(b); },
           py::is_operator())
      .def(py::pickle(&yamlOf, [](const std::string& text) { return fromYaml(text, "pickled Config"); }))
      .def("validate", &PipelineConfig::validate, "Raises ConfigError naming the first invalid key.")
      .def_property_readonly("voxel_size", [](const PipelineConfig& c) { return c.volume.voxel_size_m; },
                             "tsdf_volume.voxel_size_m")
      .def_property_readonly("truncation", [](const PipelineConfig& c) { return c.volume.truncation_m; },
                             "tsdf_volume.truncation_m")
      .def("__repr__", [](const PipelineConfig& c) {
        return "Config(voxel_size_m=" + std::to_string(c.volume.voxel_size_m) +
               ", lambda=" + std::to_string(c.integrator.lambda) + ", ...; .yaml() lists every key)";
      });
}

} // namespace msf::python
