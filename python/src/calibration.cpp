// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The rig: msf::Calibration (read from a KITTI odometry calib.txt, a raw date folder, an object
// calib file or the project's YAML, the format detected) and the pinhole camera of one image.
#include "bindings.h"

#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>
#include <msf/io/rig_file.h>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace msf::python {

namespace {

cv::Size sizeFrom(const std::optional<std::pair<int, int>>& image_size) {
  return image_size ? cv::Size(image_size->first, image_size->second) : cv::Size();
}

Calibration load(const std::filesystem::path& path, const std::optional<std::pair<int, int>>& image_size) {
  py::gil_scoped_release release;
  return loadCalibration(path.string(), sizeFrom(image_size));
}

py::array_t<double> projections(const Calibration& c) {
  py::array_t<double> P(std::vector<py::ssize_t>{4, 3, 4});
  auto out = P.mutable_unchecked<3>();
  for (int i = 0; i < 4; ++i)
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 4; ++col)
        out(i, r, col) = c.P[i](r, col);
  return P;
}

std::string describe(const Calibration& c) {
  return "Calibration('" + c.source + "', " + std::to_string(c.image_size.width) + "x" +
         std::to_string(c.image_size.height) + ", fx " + std::to_string(c.fx()) + ", baseline " +
         std::to_string(c.baselineGrey()) + " m" + (c.has_velodyne ? "" : ", cameras only") + ")";
}

PinholeCamera checkedCamera(float fx, float fy, float cx, float cy, int width, int height) {
  const PinholeCamera camera{fx, fy, cx, cy, width, height};
  if (!camera.valid())
    throw InvalidInputError("a PinholeCamera needs fx, fy > 0 and finite, cx, cy finite and a size of at least 1x1, "
                            "not fx " + std::to_string(fx) + ", fy " + std::to_string(fy) + ", cx " +
                            std::to_string(cx) + ", cy " + std::to_string(cy) + ", " + std::to_string(width) + "x" +
                            std::to_string(height));
  limits::checkImageSize(width, height, "the PinholeCamera");
  return camera;
}

/// Everything a Calibration holds, for pickle.
py::tuple calibrationState(const Calibration& c) {
  return py::make_tuple(projections(c), c.image_size.width, c.image_size.height, toArray(c.T_cam0_velo),
                        toArray(c.T_velo_imu), c.has_imu, c.has_velodyne, c.source, c.lidar.rings,
                        c.lidar.beam_elevations_deg, c.lidar.sweeping);
}

/// The Calibration of calibrationState, checked as a file's is.
Calibration calibrationFromState(const py::tuple& state) {
  if (state.size() != 11)
    throw InvalidInputError("a pickled Calibration holds 11 values, not " + std::to_string(state.size()));
  Calibration c;
  const auto P = state[0].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
  if (P.ndim() != 3 || P.shape(0) != 4 || P.shape(1) != 3 || P.shape(2) != 4)
    throw InvalidInputError("a pickled Calibration's projections must have the shape (4, 3, 4)");
  for (std::size_t i = 0; i < 4; ++i)
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 4; ++col)
        c.P[i](r, col) = P.at(static_cast<py::ssize_t>(i), r, col);
  c.image_size = cv::Size(state[1].cast<int>(), state[2].cast<int>());
  c.T_cam0_velo = poseFrom(state[3], "a pickled Calibration's T_cam0_velo");
  c.T_velo_imu = poseFrom(state[4], "a pickled Calibration's T_velo_imu");
  c.has_imu = state[5].cast<bool>();
  c.has_velodyne = state[6].cast<bool>();
  c.source = state[7].cast<std::string>();
  c.lidar.rings = state[8].cast<int>();
  c.lidar.beam_elevations_deg = state[9].cast<std::vector<double>>();
  c.lidar.sweeping = state[10].cast<bool>();
  c.validate();
  return c;
}

Calibration fromNumbers(int width, int height, double fx, double fy, double cx, double cy, double baseline,
                        const ArrayArg& T_cam_lidar, const std::optional<std::vector<double>>& beam_elevations_deg,
                        bool sweeping) {
  Calibration::Lidar lidar;
  lidar.beam_elevations_deg = beam_elevations_deg.value_or(std::vector<double>());
  lidar.sweeping = sweeping;
  if (T_cam_lidar.is_none())
    return makeRig(cv::Size(width, height), fx, fy, cx, cy, baseline, nullptr, lidar);
  const Eigen::Isometry3d T = poseFrom(T_cam_lidar, "T_cam_lidar");
  return makeRig(cv::Size(width, height), fx, fy, cx, cy, baseline, &T, lidar);
}

void bindPinholeCamera(py::module_& m) {
  py::class_<PinholeCamera> camera(m, "PinholeCamera",
                                   "The intrinsics of one rectified camera: pixel (u, v) with depth z is the point "
                                   "((u - cx) z / fx, (v - cy) z / fy, z).");
  copyable(camera)
      .def(py::init(&checkedCamera), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("width"),
           py::arg("height"))
      .def(py::pickle(
          [](const PinholeCamera& c) { return std::make_tuple(c.fx, c.fy, c.cx, c.cy, c.width, c.height); },
          [](const std::tuple<float, float, float, float, int, int>& s) { return std::apply(checkedCamera, s); }))
      .def_readwrite("fx", &PinholeCamera::fx)
      .def_readwrite("fy", &PinholeCamera::fy)
      .def_readwrite("cx", &PinholeCamera::cx)
      .def_readwrite("cy", &PinholeCamera::cy)
      .def_readwrite("width", &PinholeCamera::width)
      .def_readwrite("height", &PinholeCamera::height)
      .def_property_readonly("K", [](const PinholeCamera& c) {
        Eigen::Matrix3d K;
        K << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1;
        return K;
      }, "The 3x3 intrinsic matrix.")
      .def("__repr__", [](const PinholeCamera& c) {
        return "PinholeCamera(fx=" + std::to_string(c.fx) + ", fy=" + std::to_string(c.fy) + ", cx=" +
               std::to_string(c.cx) + ", cy=" + std::to_string(c.cy) + ", width=" + std::to_string(c.width) +
               ", height=" + std::to_string(c.height) + ")";
      });
}

} // namespace

void bindCalibration(py::module_& m) {
  bindPinholeCamera(m);
  py::class_<Calibration> calibration(m, "Calibration",
                                      "A rig: four rectified cameras (KITTI 0, 1 grey left/right; 2, 3 colour) sharing "
                                      "one image plane, and the LiDAR. Every projection maps points of camera 0's "
                                      "rectified frame to pixels.");
  copyable(calibration)
      .def(py::init(&fromNumbers), py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
           py::arg("cy"), py::arg("baseline"), py::arg("T_cam_lidar") = py::none(),
           py::arg("beam_elevations_deg") = py::none(), py::arg("sweeping") = true,
           "Your rig from its numbers, as a rig file's required keys (docs/usage.md, \"Your own rig\"): a "
           "rectified pair of width x height images, the left camera's fx, fy, cx, cy (it also colours), the right "
           "one `baseline` metres to its right; the LiDAR at T_cam_lidar (4x4: its points into the left camera; "
           "None: cameras only), its beams' elevations in degrees from the lowest (optional) and whether it sweeps. "
           "Raises CalibrationError naming what cannot be right.")
      .def(py::pickle(&calibrationState, &calibrationFromState))
      .def_static("load", &load, py::arg("path"), py::arg("image_size") = py::none(),
                  "Reads a KITTI odometry calib.txt (or its sequence folder), a KITTI raw date folder, a KITTI "
                  "object calib file or the project's YAML rig file, the format detected. image_size (width, "
                  "height) where no image lies beside the file. Raises CalibrationError naming a missing key, "
                  "IOError for a missing path.")
      .def_property_readonly("image_size", [](const Calibration& c) {
        return std::make_pair(c.image_size.width, c.image_size.height);
      }, "(width, height) of the rectified images; (0, 0) when unknown.")
      .def_property_readonly("P", &projections, "The projection matrices of cameras 0..3, shape (4, 3, 4).")
      .def_property_readonly("T_cam0_velo", [](const Calibration& c) { return toArray(c.T_cam0_velo); },
                             "The LiDAR's pose in camera 0's rectified frame, 4x4.")
      .def_property_readonly("has_velodyne", [](const Calibration& c) { return c.has_velodyne; },
                             "False for a calibration of the cameras only (no LiDAR extrinsics).")
      .def_property_readonly("source", [](const Calibration& c) { return c.source; }, "Where it was read from.")
      .def_property(
          "lidar_sweeping", [](const Calibration& c) { return c.lidar.sweeping; },
          [](Calibration& c, bool sweeping) { c.lidar.sweeping = sweeping; },
          "True for a spinning LiDAR, each scan swept over its period (the odometry deskews it, the scan's "
          "carving allows for its skew); False for scans taken at one instant. A rig file's lidar.sweeping; "
          "False for a synthetic sequence's.")
      .def_property_readonly("lidar_rings", [](const Calibration& c) { return c.lidar.rings; },
                             "The LiDAR's beams (0: unknown, the stages take them from the scans).")
      .def_property_readonly("beam_elevations_deg", [](const Calibration& c) { return c.lidar.beam_elevations_deg; },
                             "The LiDAR's beam elevations in degrees, lowest first ([]: unknown).")
      .def("K", &Calibration::K, py::arg("camera") = 0, "The 3x3 intrinsic matrix of a camera (0..3).")
      .def("baseline", &Calibration::baseline, py::arg("camera_a") = 0, py::arg("camera_b") = 1,
           "Distance between two optical centres in metres.")
      .def_property_readonly("focal_baseline", &Calibration::focalBaseline,
                             "f * B of the grey pair: depth = focal_baseline / disparity.")
      .def("camera", &PinholeCamera::fromCalibration, py::arg("camera") = 0,
           "The PinholeCamera of a camera (0..3) of the rig.")
      .def("save_yaml",
           [](const Calibration& c, const std::filesystem::path& path) { saveCalibrationYaml(c, path.string()); },
           py::arg("path"),
           "Writes the project's YAML camera file: P0..P3, the image size, the LiDAR's extrinsic and its "
           "description (sweeping, rings, beam elevations); load_calibration reads it back the same.")
      .def("__repr__", &describe);
  m.def("load_calibration", &load, py::arg("path"), py::arg("image_size") = py::none(),
        "Calibration.load: a KITTI calib.txt, raw date folder, object calib file or the project's YAML rig.");
}

} // namespace msf::python
