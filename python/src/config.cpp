// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The configuration of every stage (msf::PipelineConfig, one YAML section per stage, as in
// config/kitti.yaml) as msfusion.Config; each stage object takes its own section from it.
#include "bindings.h"

#include <msf/pipeline/pipeline_config.h>

#include <sstream>
#include <string>

namespace msf::python {

void bindConfig(py::module_& m) {
  py::class_<PipelineConfig>(m, "Config",
                             "Every stage's settings, one YAML section per stage (config/kitti.yaml lists every key). "
                             "Config() is the defaults; msfusion.load_config reads a file and overrides keys.")
      .def(py::init<>())
      .def_static("load", [](const std::filesystem::path& path) { return PipelineConfig::load(path.string()); },
                  py::arg("path"), py::call_guard<py::gil_scoped_release>(),
                  "The defaults overridden by the sections of a YAML file. Raises IOError for a missing file, "
                  "ConfigError naming a bad or unknown key.")
      .def_static("paper", &PipelineConfig::paper,
                  "The paper as published (Ali, Rajput et al. 2019), without the project's additions.")
      .def("yaml", [](const PipelineConfig& config) {
        std::ostringstream text;
        config.print(text);
        return text.str();
      }, "Every key of every section as a YAML file that Config.load reads back to the same configuration.")
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
