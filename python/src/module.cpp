// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "bindings.h"

#include <msf/common/huge_page_images.h>
#include <msf/common/version.h>

#include <opencv2/core/utility.hpp>

PYBIND11_MODULE(_core, m) {
  m.doc() = "msfusion's library on numpy arrays (the package msfusion re-exports it; see help(msfusion))";
  using namespace msf::python;
  m.attr("__version__") = msf::versionString();  // the C++ library's, "MAJOR.MINOR.PATCH"
  m.attr("__commit__") = msf::gitCommit();       // what the tools' --version names
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
  m.def(
      "_rigid_pose",
      [](const py::handle& pose, const std::string& name) { return toArray(poseFrom(pose, name.c_str())); },
      py::arg("pose"), py::arg("name"),
      "A 4x4 float64 copy of `pose`; InvalidInputError naming `name` when it is not a rigid transform, as every "
      "function that takes a pose checks it.");
  m.def("use_huge_pages_for_large_images", &msf::useHugePagesForLargeImages,
        "Images of 1 MiB or more on transparent huge pages, for the rest of the process, as the tools have them: "
        "fewer page faults for the images each frame allocates. The same values; it changes OpenCV's allocator "
        "for everything in the process.");
}
