// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "bindings.h"

#include <opencv2/core/utility.hpp>

PYBIND11_MODULE(_core, m) {
  m.doc() = "msfusion's library on numpy arrays (the package msfusion re-exports it; see help(msfusion))";
  using namespace msf::python;
  bindErrors(m);
  bindCalibration(m);
  bindConfig(m);
  bindStages(m);
  bindMesh(m);
  bindTsdf(m);
  bindDepthClouds(m);
  bindFrames(m);
  bindReconstructor(m);
  m.def("set_num_threads", &cv::setNumThreads, py::arg("threads"),
        "Threads of the library's parallel loops (OpenCV's pool, shared by every object): n, 1 or 0 = "
        "the calling thread only, negative = all the cores (the default).");
  m.def("get_num_threads", &cv::getNumThreads, "Threads of the library's parallel loops.");
}
