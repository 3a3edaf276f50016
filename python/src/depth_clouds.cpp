// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The organized clouds the msf_* tools write (msf_interpolate, msf_stereo, msf_fuse,
// msf_reconstruct -save_depth) as depth, weight and colour arrays: what a notebook needs to look
// at a tool's output or to compare it with its own.
#include "bindings.h"

#include <msf/io/cloud_io.h>
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/depth_frame.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <optional>
#include <string>

namespace msf::python {

namespace {

py::tuple readDepthCloud(const std::string& path, const std::optional<PinholeCamera>& camera) {
  DepthFrame frame;
  {
    py::gil_scoped_release release;
    pcl::PCLPointCloud2 cloud;
    loadCloudBlob(path, cloud);
    frame = toDepthFrame(cloud, camera ? &*camera : nullptr, "cloud '" + path + "'");
    if (!frame.color.empty())
      cv::cvtColor(frame.color, frame.color, cv::COLOR_BGR2RGB);
  }
  return py::make_tuple(toArray(frame.depth), toArray(frame.weight), toArray(frame.color));
}

} // namespace

void bindDepthClouds(py::module_& m) {
  m.def("read_depth_cloud", &readDepthCloud, py::arg("path"), py::arg("camera") = py::none(),
        "An organized .pcd of camera 0 (msf_interpolate's, msf_stereo's, msf_fuse's) as (depth, weight, color): "
        "(H, W) float32 z in metres (0 where NaN), (H, W) float32 from the field weight or None, (H, W, 3) uint8 RGB "
        "or None. `camera` (a PinholeCamera) skips fitting the intrinsics to the points. Raises IOError naming the "
        "file, InvalidInputError for a cloud that is not organized.");
}

} // namespace msf::python
