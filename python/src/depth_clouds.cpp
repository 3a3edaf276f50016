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

py::tuple readDepthCloud(const std::filesystem::path& file, const std::optional<PinholeCamera>& camera) {
  const std::string path = file.string();
  DepthFrame frame;
  cv::Mat sky_depth;
  {
    py::gil_scoped_release release;
    pcl::PCLPointCloud2 cloud;
    loadCloudBlob(path, cloud);
    const std::string what = "cloud '" + path + "'";
    frame = toDepthFrame(cloud, camera ? &*camera : nullptr, what);
    sky_depth = readSkyDepth(cloud, what);
    if (!frame.color.empty())
      cv::cvtColor(frame.color, frame.color, cv::COLOR_BGR2RGB);
  }
  return py::make_tuple(toArray(frame.depth), toArray(frame.weight), toArray(frame.color),
                        toArray(frame.free_space_weight), toArray(sky_depth));
}

} // namespace

void bindDepthClouds(py::module_& m) {
  m.def("_read_depth_cloud", &readDepthCloud, py::arg("path"), py::arg("camera") = py::none(),
        "(depth, weight, color, free_space_weight, sky_depth) of an organized .pcd: msfusion.read_depth_cloud's "
        "arrays, each None where the cloud has no such field.");
}

} // namespace msf::python
