// The whole method per frame on the caller's thread (msf::Pipeline::computeDepth, integrate,
// updateMesh): a Frame in, its depth images (msf::FrameResult) out, the map and its mesh kept.
#include "bindings.h"
#include "frame_object.h"

#include <msf/pipeline/pipeline.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <mutex>

namespace msf::python {

namespace {

struct PipelineObject {
  PipelineObject(const Calibration& calibration, const PipelineConfig& config) : pipeline(calibration, config) {}
  Pipeline pipeline;
  std::mutex mutex;
};

/// The result a Python object keeps: its own copy of the left image when that is a view of the
/// caller's array, which may be gone before the result is.
FrameResult keepable(FrameResult result, const FrameObject& frame) {
  if (!frame.arrays.is_none())
    result.left = result.left.clone();
  result.name = frame.name;
  return result;
}

FrameResult computeDepth(PipelineObject& p, const FrameObject& frame) {
  return keepable(withoutGil(p.mutex, [&] { return p.pipeline.computeDepth(frame.frame); }), frame);
}

void integrate(PipelineObject& p, FrameResult& result) {
  withoutGil(p.mutex, [&] { p.pipeline.integrate(result); });
}

FrameResult addFrame(PipelineObject& p, const FrameObject& frame) {
  return keepable(withoutGil(p.mutex, [&] {
    FrameResult result = p.pipeline.computeDepth(frame.frame);
    p.pipeline.integrate(result);
    return result;
  }), frame);
}

TriangleMesh updateMesh(PipelineObject& p) {
  return withoutGil(p.mutex, [&] { return p.pipeline.updateMesh(); }); // a copy: the pipeline keeps its own
}

/// A property of FrameResult viewing one of its images.
template <cv::Mat FrameResult::*image>
py::object imageOf(const py::handle& self) {
  return viewOf(self.cast<const FrameResult&>().*image, self);
}

void bindFrameResult(py::module_& m) {
  py::class_<FrameResult>(m, "FrameResult",
                          "What one frame produced: depth images of camera 0, (H, W) float32 metres (0 = none), "
                          "each a view of the result (no copy).")
      .def_property_readonly("index", [](const FrameResult& r) { return r.index; })
      .def_property_readonly("name", [](const FrameResult& r) { return r.name; })
      .def_property("pose", [](const FrameResult& r) -> py::object {
        return r.has_pose ? py::object(toArray(r.T_world_cam0)) : py::none();
      }, [](FrameResult& r, const py::handle& pose) {
        r.has_pose = !pose.is_none();
        r.T_world_cam0 = r.has_pose ? poseFrom(pose, "pose") : Eigen::Isometry3d::Identity();
      }, "T_world_cam0 (4x4) at which the frame is integrated, or None; settable before integrate().")
      .def_property_readonly("depth", [](const py::handle& self) {
        return viewOf(self.cast<const FrameResult&>().fused.depth, self);
      }, "The fused depth (step 4).")
      .def_property_readonly("weight", [](const py::handle& self) {
        return viewOf(self.cast<const FrameResult&>().fused.weight, self);
      }, "The fused depth's inverse variance, m^-2.")
      .def_property_readonly("free_space_weight", [](const py::handle& self) {
        return viewOf(self.cast<const FrameResult&>().fused.free_space_weight, self);
      }, "The weight of the free space in front of each fused depth.")
      .def_property_readonly("color", [](const FrameResult& r) -> py::object {
        if (r.fused.color.empty())
          return py::none();
        cv::Mat rgb;
        cv::cvtColor(r.fused.color, rgb, cv::COLOR_BGR2RGB);
        return toArray(rgb);
      }, "The colour of each fused pixel, (H, W, 3) uint8 RGB (a copy).")
      .def_property_readonly("left", &imageOf<&FrameResult::left>, "Camera 0's grey image.")
      .def_property_readonly("lidar_depth", &imageOf<&FrameResult::lidar_depth>, "The interpolated LiDAR (step 2).")
      .def_property_readonly("lidar_distance", &imageOf<&FrameResult::lidar_distance>,
                             "Pixels from each pixel to the nearest real LiDAR return.")
      .def_property_readonly("stereo_depth", &imageOf<&FrameResult::stereo_depth>, "SGBM's depth (step 3).")
      .def_property_readonly("stereo_confidence", &imageOf<&FrameResult::stereo_confidence>,
                             "SGBM's confidence in [0, 1].")
      .def_property_readonly("times", [](const FrameResult& r) {
        const StageTimes& t = r.times;
        py::dict times;
        times["load_ms"] = t.load_ms;
        times["lidar_ms"] = t.lidar_ms;
        times["stereo_ms"] = t.stereo_ms;
        times["depth_ms"] = t.depth_ms;
        times["fusion_ms"] = t.fusion_ms;
        times["integrate_ms"] = t.integrate_ms;
        return times;
      }, "Milliseconds per stage.")
      .def("__repr__", [](const FrameResult& r) {
        return "FrameResult('" + r.name + "', " + std::to_string(r.fused.depth.cols) + "x" +
               std::to_string(r.fused.depth.rows) + (r.has_pose ? "" : ", no pose") + ")";
      });
}

} // namespace

void bindPipeline(py::module_& m) {
  bindFrameResult(m);
  py::class_<PipelineObject>(m, "Pipeline",
                             "The whole method, frame by frame on the calling thread: LiDAR completion and SGBM, "
                             "fused per pixel (compute_depth), integrated into the regularized TSDF volume at the "
                             "frame's pose (integrate), meshed incrementally (update_mesh). The same classes and "
                             "settings as msf_reconstruct, so the same depth and mesh.")
      .def(py::init<const Calibration&, const PipelineConfig&>(), py::arg("calibration"),
           py::arg("config") = PipelineConfig(),
           "Raises ConfigError for an invalid config, CalibrationError for a rig without an image size.")
      .def("compute_depth", &computeDepth, py::arg("frame"),
           "Steps 1-4 of a Frame: its FrameResult (fused depth and weight, and each stage's depth). Raises "
           "InvalidInputError for images or a scan that do not fit the calibration.")
      .def("integrate", &integrate, py::arg("result"),
           "Step 5: the result's fused depth at its pose into the map. Raises InvalidInputError without a pose.")
      .def("add_frame", &addFrame, py::arg("frame"), "compute_depth, then integrate: the frame's FrameResult.")
      .def("update_mesh", &updateMesh, "The map's Mesh, meshing again only the blocks changed since the last call.")
      .def_property_readonly("calibration", [](PipelineObject& p) { return p.pipeline.calibration(); })
      .def_property_readonly("config", [](PipelineObject& p) { return p.pipeline.config(); })
      .def_property_readonly("num_blocks", [](PipelineObject& p) {
        return withoutGil(p.mutex, [&] { return p.pipeline.volume().numBlocks(); });
      }, "Blocks of 8^3 voxels the map holds.");
}

} // namespace msf::python
