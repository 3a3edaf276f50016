// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The binding layer of the module msfusion._core: one function per concept, called in this
// order by PYBIND11_MODULE (module.cpp); each file binds its classes with numpy in and out.
#include "arrays.h"

#include <pybind11/stl/filesystem.h> // a path argument takes str or os.PathLike (pathlib.Path)

namespace msf::python {

/// copy.copy and copy.deepcopy of a class that holds all its data by value: a C++ copy.
template <typename Class>
Class& copyable(Class& cls) {
  using T = typename Class::type;
  cls.def("__copy__", [](const T& value) { return T(value); });
  cls.def("__deepcopy__", [](const T& value, const py::dict&) { return T(value); }, py::arg("memo"));
  return cls;
}

void bindErrors(py::module_& m);       // errors.cpp: msf::Error and its kinds
void bindCalibration(py::module_& m);  // calibration.cpp: Calibration, PinholeCamera
void bindConfig(py::module_& m);       // config.cpp: PipelineConfig as Config
void bindStages(py::module_& m);       // stages.cpp: steps 1-4 on arrays
void bindMesh(py::module_& m);         // mesh.cpp: TriangleMesh as Mesh, read_mesh
void bindTsdf(py::module_& m);         // tsdf.cpp: TsdfVolume with its integrator and mesher
void bindDepthClouds(py::module_& m);  // depth_clouds.cpp: the organized clouds the msf_* tools write
void bindFrames(py::module_& m);       // frames.cpp: Frame, FrameSource, Sequence, open_dataset
void bindReconstructor(py::module_& m);  // reconstructor.cpp: the engine, FrameResult

} // namespace msf::python
