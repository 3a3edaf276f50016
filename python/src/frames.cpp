// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Frames in: msf::Frame as msfusion.Frame (loaded from a source, or made from arrays: grey pair,
// scan, colour image, pose), and msf::FrameSource (msf::Sequence: a KITTI odometry sequence or
// raw drive, or the synthetic street; open_dataset) as an iterable of frames.
#include "bindings.h"
#include "frame_object.h"

#include <msf/common/exceptions.h>
#include <msf/datasets/open_dataset.h>
#include <msf/io/image_io.h>
#include <msf/io/sequence.h>
#include <msf/io/bag_options.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace msf::python {

namespace {

FrameObject fromArrays(const ArrayArg& left, const ArrayArg& right, const ArrayArg& scan,
                       const ArrayArg& color, const ArrayArg& pose, std::optional<std::size_t> index,
                       double timestamp, const std::string& name) {
  FrameObject object;
  Frame& frame = object.frame;
  frame.index = index.value_or(0);
  object.numbered = index.has_value();
  frame.timestamp = timestamp;
  // A 10- to 16-bit camera's uint16 images are scaled to 8 bits as the folder and bag readers
  // scale them: by the bits the brighter image of the pair needs, one gain for both.
  const int depth = hasDepth(left, CV_16U) ? CV_16U : CV_8U;
  frame.left = imageView(left, "left", CV_MAKETYPE(depth, 1));
  frame.right = imageView(right, "right", CV_MAKETYPE(depth, 1), frame.left.size());
  const cv::Mat points = scanView(scan);
  const int color_depth = hasDepth(color, CV_16U) ? CV_16U : CV_8U;
  cv::Mat rgb = optionalImageView(color, "color", CV_MAKETYPE(color_depth, 3));
  if (!pose.is_none()) {
    frame.T_world_cam0 = poseFrom(pose, "pose");
    frame.has_pose = true;
  }
  {
    py::gil_scoped_release release;
    frame.scan = scanFromPoints(points);
    if (depth == CV_16U) {
      const int bits = pairBits(frame.left, frame.right);
      frame.left = toEightBit(frame.left, bits);
      frame.right = toEightBit(frame.right, bits);
    }
    if (color_depth == CV_16U)
      rgb = toEightBit(rgb, significantBits(rgb));
    if (!rgb.empty())
      cv::cvtColor(rgb, frame.color, cv::COLOR_RGB2BGR); // the library's order
  }
  object.name = name.empty() ? std::to_string(frame.index) : name;
  // The frame views the caller's arrays, unless they were scaled to 8 bits into its own images.
  object.arrays = depth == CV_8U ? py::object(py::make_tuple(left, right)) : py::object(py::none());
  return object;
}


FrameObject load(const FrameSource& source, long long i, bool with_color) {
  const std::size_t index = frameIndex(source, i);
  FrameObject object;
  {
    py::gil_scoped_release release;
    object.frame = source.load(index, with_color);
  }
  object.name = source.frameName(index);
  object.arrays = py::none();
  return object;
}

/// Camera 0's or 1's image: for a frame made from arrays the caller's own array (its flags, a
/// read-only one included, stay its own), else a view of the frame's.
py::object greyImage(const py::handle& self, int camera) {
  const FrameObject& f = self.cast<const FrameObject&>();
  if (py::isinstance<py::tuple>(f.arrays))
    return py::reinterpret_borrow<py::tuple>(f.arrays)[static_cast<std::size_t>(camera)];
  return viewOf(camera == 0 ? f.frame.left : f.frame.right, self);
}

/// for frame in source: loads frame after frame.
struct FrameIterator {
  py::object source;  // keeps the FrameSource alive
  std::size_t next = 0;
};

py::object posesOf(const FrameSource& source) {
  if (!source.hasPoses())
    return py::none();
  const PoseList& poses = source.poses();
  py::array_t<double> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(poses.size()), 4, 4});
  auto o = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        o(static_cast<py::ssize_t>(i), r, c) = poses[i].matrix()(r, c);
  return std::move(out);
}

void bindFrame(py::module_& m) {
  py::class_<FrameObject>(m, "Frame",
                          "One frame: the rectified grey pair of cameras 0 and 1, the LiDAR scan, the colour camera's "
                          "image and the pose of camera 0 (T_world_cam0), if any.")
      .def(py::init(&fromArrays), py::arg("left"), py::arg("right"), py::arg("scan"), py::arg("color") = py::none(),
           py::arg("pose") = py::none(), py::arg("index") = py::none(), py::arg("timestamp") = 0.0, py::arg("name") = "",
           "A frame from arrays: left, right (H, W) uint8 grey (viewed, not copied), or uint16 of a 10- to 16-bit "
           "camera (scaled to 8 bits by the bits the brighter image needs, one gain for both, as the dataset "
           "readers scale them), scan (N, 4) float32 (or float64) x y z reflectance in the LiDAR's frame or "
           "(N, 3), color (H, W, 3) uint8 (or uint16) RGB of the colour camera (the rectified cameras share one "
           "image size), pose 4x4 T_world_cam0 (None: no pose); index None: an engine's add_frame numbers it by "
           "its place among the frames it was given.")
      .def_property_readonly("index", [](const FrameObject& f) { return f.frame.index; })
      .def_property_readonly("name", [](const FrameObject& f) { return f.name; }, "File stem ('000042').")
      .def_property_readonly("timestamp", [](const FrameObject& f) { return f.frame.timestamp; },
                             "Seconds from the sequence's first frame.")
      .def_property_readonly("left", [](const py::handle& self) { return greyImage(self, 0); },
                             "Camera 0's grey image, (H, W) uint8 (a view; the array given, for a frame from arrays).")
      .def_property_readonly("right", [](const py::handle& self) { return greyImage(self, 1); },
                             "Camera 1's grey image, (H, W) uint8 (a view; the array given, for a frame from arrays).")
      .def_property_readonly("color", [](const FrameObject& f) -> py::object {
        if (f.frame.color.empty())
          return py::none();
        cv::Mat rgb;
        cv::cvtColor(f.frame.color, rgb, cv::COLOR_BGR2RGB);
        return toArray(rgb);
      }, "The colour camera's image, (H, W, 3) uint8 RGB (a copy), or None.")
      .def_property_readonly("scan", [](const FrameObject& f) -> py::object {
        if (!f.frame.scan)
          return py::none();
        return toArray(*f.frame.scan);
      }, "The LiDAR scan, (N, 4) float32 x y z reflectance in the LiDAR's frame (a copy).")
      .def_property_readonly("pose", [](const FrameObject& f) -> py::object {
        if (!f.frame.has_pose)
          return py::none();
        return toArray(f.frame.T_world_cam0);
      }, "T_world_cam0, 4x4 float64, or None.")
      .def("__repr__", [](const FrameObject& f) {
        return "Frame('" + f.name + "', " + std::to_string(f.frame.left.cols) + "x" + std::to_string(f.frame.left.rows) +
               ", " + std::to_string(f.frame.scan ? f.frame.scan->size() : 0) + " points" +
               (f.frame.has_pose ? "" : ", no pose") + ")";
      });
}

void bindSources(py::module_& m) {
  py::class_<FrameIterator>(m, "_FrameIterator")
      .def("__iter__", [](const py::handle& self) { return self; })
      .def("__next__", [](FrameIterator& it) {
        const FrameSource& source = it.source.cast<const FrameSource&>();
        if (it.next >= source.size())
          throw py::stop_iteration();
        return load(source, static_cast<long long>(it.next++), true);
      });
  py::class_<FrameSource>(m, "FrameSource",
                          "Where frames come from (a dataset folder): its rig, its frames by index or one after "
                          "the other, and its poses, if any.")
      .def("__len__", &FrameSource::size)
      .def("__getitem__", [](const FrameSource& s, long long i) { return load(s, i, true); }, py::arg("index"))
      .def("__getitem__", [](const FrameSource& s, const py::slice& slice) {
        std::size_t start = 0, stop = 0, step = 0, count = 0;
        if (!slice.compute(s.size(), &start, &stop, &step, &count))
          throw py::error_already_set();
        py::list frames;
        for (std::size_t k = 0; k < count; ++k)
          frames.append(load(s, static_cast<long long>(start + k * step), true));
        return frames;
      }, py::arg("frames"), "A list of the frames of a slice, each loaded.")
      .def("load", &load, py::arg("index"), py::arg("with_color") = true,
           "Frame `index`; with_color=False skips reading the colour camera.")
      .def("__iter__", [](const py::object& self) { return FrameIterator{self, 0}; })
      .def_property_readonly("calibration", [](const FrameSource& s) { return s.calibration(); },
                             "A copy of the source's rig: changing it leaves the source as it is.")
      .def_property_readonly("poses", &posesOf, "(N, 4, 4) float64 T_world_cam0 per frame, or None.")
      .def_property_readonly("has_color", &FrameSource::hasColor, "Whether its frames have a colour camera's image.")
      .def_property_readonly("notes", &FrameSource::notes,
                             "What reading it left out or took from the data, a line each (a bag's skipped scans, "
                             "the beams a rig without them took from the scans' rings).")
      .def("frame_name", [](const FrameSource& s, long long i) { return s.frameName(frameIndex(s, i)); },
           py::arg("index"), "The file stem of frame `index` ('000042').")
      .def("__repr__", [](const FrameSource& s) {
        return "FrameSource('" + s.description() + "', " + std::to_string(s.size()) + " frames)";
      });
  py::class_<Sequence, FrameSource>(m, "Sequence",
                                    "A dataset on disk, its layout detected: a KITTI odometry sequence (sequences/XX "
                                    "with poses/XX.txt), a KITTI raw drive (YYYY_MM_DD_drive_NNNN_sync, calibration "
                                    "in the date folder, poses from OXTS) or msf_synth's synthetic street. "
                                    "Indexing loads a Frame; iterating loads one after the other.")
      .def(py::init([](const std::filesystem::path& path) { return std::make_unique<Sequence>(path.string()); }),
           py::arg("path"), py::call_guard<py::gil_scoped_release>(),
           "Raises IOError naming the folder when it is no known layout.")
      .def_property_readonly("directory", &Sequence::directory)
      .def_property_readonly("layout", [](const Sequence& s) {
        return s.layout() == Sequence::Layout::Raw ? "raw" : "odometry";
      })
      .def("__repr__", [](const Sequence& s) {
        return "Sequence('" + s.directory() + "', " + std::to_string(s.size()) + " frames)";
      });
  const BagOptions kitti2bag;
  m.def(
      "open_dataset",
      [](const std::filesystem::path& path, const std::optional<std::filesystem::path>& rig,
         const std::string& lidar_topic, const std::string& left_topic, const std::string& right_topic,
         const std::string& color_topic, const std::string& world_frame, double max_offset,
         std::optional<bool> sweeping_scans) {
        py::gil_scoped_release release;
        DatasetOptions options;
        options.rig = rig ? rig->string() : "";
        options.bag = {lidar_topic, left_topic, right_topic, color_topic, world_frame, max_offset, sweeping_scans};
        return openDataset(path.string(), options);
      },
      py::arg("path"), py::arg("rig") = py::none(), py::kw_only(), py::arg("lidar_topic") = kitti2bag.lidar_topic,
      py::arg("left_topic") = kitti2bag.left_topic, py::arg("right_topic") = kitti2bag.right_topic,
      py::arg("color_topic") = kitti2bag.color_topic, py::arg("world_frame") = kitti2bag.world_frame,
      py::arg("max_offset") = kitti2bag.max_offset_s, py::arg("sweeping_scans") = py::none(),
      "The FrameSource of a dataset, its layout detected (as msf_reconstruct reads it): a folder, or a ROS 1 bag "
      "read by its topics (kitti2bag's by default; color_topic '' for none), tf's world_frame ('' = camera_init, "
      "else the root of the left camera's tree), the largest offset in seconds between a scan and its images, and "
      "whether its LiDAR sweeps its scans (None: it does); rig: a calibration or rig file for layouts without one, "
      "or to override the dataset's.");
}

} // namespace

std::size_t frameIndex(const FrameSource& source, long long i) {
  const auto size = static_cast<long long>(source.size());
  if (i < -size || i >= size)
    throw py::index_error("frame " + std::to_string(i) + " of a source of " + std::to_string(size));
  return static_cast<std::size_t>(i < 0 ? i + size : i);
}

void bindFrames(py::module_& m) {
  bindFrame(m);
  bindSources(m);
}

} // namespace msf::python
