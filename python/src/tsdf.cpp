// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Step 5 on arrays: a sparse TSDF volume (msf::TsdfVolume) with its integrator (depth images or
// points at a 4x4 pose, the regularized update of eq. 7) and its incremental mesher (marching
// cubes), as one object: VDBFusion's VDBVolume, with msfusion's integration.
#include "bindings.h"

#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace msf::python {

namespace {

struct Tsdf {
  Tsdf(const PipelineConfig& config, double voxel_size_m, double truncation_m)
      : volume(voxel_size_m, truncation_m), integrator(volume, config.integrator), mesher(config.mesher),
        free_space_weight(config.fusion.lidarRangeWeight()) {
    volume.setMaxMemoryMb(config.volume.max_memory_mb);
  }
  TsdfVolume volume;
  TsdfIntegrator integrator;  // writes `volume`
  MarchingCubes mesher;       // remembers each block's mesh: extract_mesh meshes only what changed
  float free_space_weight;    // of the open sky's and the far rays' carving: the LiDAR's, as the engine's
  std::mutex mutex;
};

std::unique_ptr<Tsdf> makeTsdf(const PipelineConfig& given, std::optional<double> voxel_size,
                               std::optional<double> truncation, const std::optional<Calibration>& calibration) {
  const PipelineConfig config = calibration ? adaptToRig(given, *calibration) : given;
  return std::make_unique<Tsdf>(config, voxel_size.value_or(config.volume.voxel_size_m),
                                truncation.value_or(config.volume.truncation_m));
}

/// A PinholeCamera, or camera 0 of a Calibration.
PinholeCamera cameraFrom(const py::handle& camera) {
  if (py::isinstance<Calibration>(camera))
    return PinholeCamera::fromCalibration(camera.cast<const Calibration&>(), 0);
  if (py::isinstance<PinholeCamera>(camera))
    return camera.cast<PinholeCamera>();
  throw InvalidInputError("camera must be a msfusion.PinholeCamera or a msfusion.Calibration (its camera 0), got " +
                          py::str(camera.get_type().attr("__name__")).cast<std::string>());
}

void integrateDepth(Tsdf& tsdf, const ArrayArg& depth, const ArrayArg& pose, const CameraArg& camera,
                    const ArrayArg& weight, const ArrayArg& color, const ArrayArg& free_space_weight,
                    const ArrayArg& sky_depth) {
  DepthFrame frame;
  frame.camera = cameraFrom(camera);
  const cv::Size size(frame.camera.width, frame.camera.height);
  frame.depth = imageView(depth, "depth", CV_32FC1, size);
  frame.weight = optionalImageView(weight, "weight", CV_32FC1, size);
  frame.free_space_weight = optionalImageView(free_space_weight, "free_space_weight", CV_32FC1, size);
  const cv::Mat rgb = optionalImageView(color, "color", CV_8UC3, size);
  const cv::Mat sky = optionalImageView(sky_depth, "sky_depth", CV_32FC1, size);
  requireDepthValues(frame.depth, "depth");
  requireWeightValues(frame.weight, "weight");
  requireWeightValues(frame.free_space_weight, "free_space_weight");
  const Eigen::Isometry3d T_world_cam = poseFrom(pose, "pose");
  withoutGil(tsdf.mutex, [&] {
    if (!rgb.empty())
      cv::cvtColor(rgb, frame.color, cv::COLOR_RGB2BGR); // the volume keeps OpenCV's order
    // What msf_integrate does with a fused cloud: the depth, then the free space of its open
    // sky and of its rays beyond the range (each as the configuration's carving allows).
    TsdfIntegrator::FreeSpace free;
    free.weight = tsdf.free_space_weight;
    free.sky_depth = sky;
    free.sky_camera = frame.camera;
    tsdf.integrator.integrateFrame(frame, T_world_cam, free);
  });
}

void integratePoints(Tsdf& tsdf, const ArrayArg& points, const ArrayArg& pose, const ArrayArg& colors) {
  const cv::Mat p = rowsView(points, "points", CV_32F, 3, 4);
  const cv::Mat c = colors.is_none() ? cv::Mat() : rowsView(colors, "colors", CV_8U, 3, 3);
  if (!c.empty() && c.rows != p.rows)
    throw InvalidInputError("colors has " + std::to_string(c.rows) + " rows for " + std::to_string(p.rows) + " points");
  const Eigen::Isometry3d T_world_sensor = poseFrom(pose, "pose");
  withoutGil(tsdf.mutex, [&] {
    // What TsdfIntegrator::integrateScan does with a PCL cloud: the finite points, into the world.
    const Eigen::Isometry3f T = T_world_sensor.cast<float>();
    std::vector<Eigen::Vector3f> points_world;
    std::vector<cv::Vec3b> colors_bgr;
    points_world.reserve(static_cast<std::size_t>(p.rows));
    for (int i = 0; i < p.rows; ++i) {
      const Eigen::Vector3f q(p.at<float>(i, 0), p.at<float>(i, 1), p.at<float>(i, 2));
      if (!q.allFinite())
        continue;
      points_world.push_back(T * q);
      if (!c.empty())
        colors_bgr.emplace_back(c.at<std::uint8_t>(i, 2), c.at<std::uint8_t>(i, 1), c.at<std::uint8_t>(i, 0));
    }
    tsdf.integrator.integrateRays(points_world, colors_bgr, T_world_sensor.translation());
  });
}

TriangleMesh extractMesh(Tsdf& tsdf) {
  TriangleMesh mesh;
  withoutGil(tsdf.mutex, [&] { tsdf.mesher.extract(tsdf.volume, mesh); });
  return mesh;
}

} // namespace

void bindTsdf(py::module_& m) {
  const PipelineConfig defaults;
  py::class_<Tsdf>(m, "TsdfVolume",
                   "A sparse, boundless TSDF volume with its integrator and incremental mesher (step 5). Takes the "
                   "sections tsdf_volume, tsdf_integrator and marching_cubes of `config`; voxel_size and "
                   "truncation (metres) override the first; with the rig's `calibration`, the keys are adapted to "
                   "it as the engine adapts them (adaptToRig: tsdf_integrator.max_depth_m, by its stereo's range).")
      .def(py::init(&makeTsdf), py::arg("config") = defaults, py::arg("voxel_size") = py::none(),
           py::arg("truncation") = py::none(), py::arg("calibration") = py::none())
      .def("integrate", &integrateDepth, py::arg("depth"), py::arg("pose"), py::arg("camera"),
           py::arg("weight") = py::none(), py::arg("color") = py::none(), py::arg("free_space_weight") = py::none(),
           py::arg("sky_depth") = py::none(),
           "A depth image seen from `pose` (4x4 T_world_cam): depth (H, W) float32 metres (0 = none), camera a "
           "PinholeCamera (or a Calibration: its camera 0) of that size; optional (H, W) float32 weight (inverse "
           "variance, m^-2: DepthFusion's) and free_space_weight, (H, W, 3) uint8 RGB color, (H, W) float32 "
           "sky_depth (a DepthCloud's: NaN where not open sky, else the depth its ray is carved to in front of, +inf "
           "for the whole ray; 0 or below is refused). As msf_integrate does, the rays of the open sky "
           "and those beyond tsdf_integrator.max_depth_m then carve the free space they passed (sky_carving, "
           "far_carving, with space_carving).")
      .def("integrate_points", &integratePoints, py::arg("points"), py::arg("pose"), py::arg("colors") = py::none(),
           "Points (N, 3) or (N, 4) float32 in the sensor's frame, the sensor at `pose` (4x4 T_world_sensor): each "
           "point's ray from the sensor updates the voxels around it (VDBFusion's integrate(points, origin)). "
           "Optional colours (N, 3) uint8 RGB.")
      .def("extract_mesh", &extractMesh,
           "The mesh of the volume (marching cubes, welded, coloured), meshing again only the blocks changed since "
           "the last call.")
      .def("save", [](Tsdf& tsdf, const std::filesystem::path& path) {
        withoutGil(tsdf.mutex, [&] { tsdf.volume.save(path.string()); });
      }, py::arg("path"), "The observed voxels as a .pcd of x y z sdf weight rgb (msf_mesh meshes it).")
      .def_property_readonly("voxel_size", [](const Tsdf& t) { return t.volume.voxelSize(); })
      .def_property_readonly("truncation", [](const Tsdf& t) { return t.volume.truncation(); })
      .def_property_readonly("num_blocks", [](Tsdf& t) {
        return withoutGil(t.mutex, [&] { return t.volume.numBlocks(); });
      }, "Allocated blocks of 8^3 voxels.")
      .def_property_readonly("num_observed_voxels", [](Tsdf& t) {
        return withoutGil(t.mutex, [&] { return t.volume.numObservedVoxels(); });
      }, "Voxels with a weight > 0.")
      .def_property_readonly("memory_bytes", [](Tsdf& t) {
        return withoutGil(t.mutex, [&] { return t.volume.memoryBytes(); });
      }, "Bytes held by the blocks and their map.")
      .def("__repr__", [](const Tsdf& t) {
        return "TsdfVolume(voxel_size=" + std::to_string(t.volume.voxelSize()) +
               ", truncation=" + std::to_string(t.volume.truncation()) + ", " + std::to_string(t.volume.numBlocks()) +
               " blocks)";
      });
}

} // namespace msf::python
