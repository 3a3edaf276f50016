// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The engine (msf::Reconstructor) as msfusion.Reconstructor: frames one call at a time on the
// caller's thread (add_frame: depth, pose, integration; mesh()), or a source's frames overlapped
// on the engine's threads (run), each frame's depth images given back as a FrameResult.
#include "bindings.h"
#include "frame_list.h"
#include "frame_object.h"

#include <msf/common/exceptions.h>
#include <msf/pipeline/reconstructor.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace msf::python {

namespace {

struct Engine {
  Engine(const Calibration& rig, const PipelineConfig& config, const Reconstructor::Options& options)
      : engine(rig, config, options) {}
  Reconstructor engine;
  std::size_t frames_added = 0; // by add_frame: the index of a frame made of arrays without one
  /// Calls from several Python threads take turns; run() holds it on its own thread, where its
  /// on_frame callback may call mesh() or num_blocks (the engine refuses the others there).
  std::recursive_mutex mutex;
  std::size_t notes_said = 0; // the engine's notes raised as warnings so far
};

/// The engine's new notes as Python warnings (UserWarning), each once; with the GIL.
void warnOfNewNotes(Engine& e) {
  const std::vector<std::string> notes = withoutGil(e.mutex, [&] { return e.engine.notes(); });
  for (; e.notes_said < notes.size(); ++e.notes_said)
    if (PyErr_WarnEx(PyExc_UserWarning, ("msfusion.Reconstructor: " + notes[e.notes_said]).c_str(), 1) != 0)
      throw py::error_already_set(); // a filter that turns warnings into errors
}

Reconstructor::PoseMode parsePoseMode(const std::string& text) {
  if (text == "auto")
    return Reconstructor::PoseMode::Auto;
  if (text == "given")
    return Reconstructor::PoseMode::Given;
  if (text == "odometry")
    return Reconstructor::PoseMode::Odometry;
  if (text == "refine")
    return Reconstructor::PoseMode::Refine;
  throw InvalidInputError("poses must be auto, given, odometry or refine, not '" + text + "'");
}

std::unique_ptr<Engine> makeEngine(const Calibration& rig, const PipelineConfig& config, const std::string& poses,
                                   int threads, const std::optional<std::filesystem::path>& stream_directory) {
  Reconstructor::Options options;
  options.poses = parsePoseMode(poses);
  options.threads = threads;
  options.stream_directory = stream_directory ? stream_directory->string() : "";
  py::gil_scoped_release release;
  return std::make_unique<Engine>(rig, config, options);
}

/// The result a Python object keeps: its own copy of the left image when that is a view of the
/// caller's array, which may be gone before the result is.
FrameResult keepable(FrameResult result, const FrameObject& frame) {
  if (!frame.arrays.is_none())
    result.left = result.left.clone();
  result.name = frame.numbered ? frame.name : std::to_string(result.index);
  return result;
}

FrameResult addFrame(Engine& e, const FrameObject& object) {
  FrameResult added = keepable(withoutGil(e.mutex, [&] {
                                 Frame numbered;
                                 if (!object.numbered) {
                                   numbered = object.frame; // shares its images and scan
                                   numbered.index = e.frames_added;
                                 }
                                 FrameResult result = e.engine.addFrame(object.numbered ? object.frame : numbered);
                                 ++e.frames_added;
                                 return result;
                               }),
                               object);
  warnOfNewNotes(e);
  return added;
}

FrameResult computeDepth(Engine& e, const FrameObject& frame) {
  return keepable(withoutGil(e.mutex, [&] { return e.engine.computeDepth(frame.frame); }), frame);
}

void integrate(Engine& e, FrameResult& result) {
  withoutGil(e.mutex, [&] { e.engine.integrate(result); });
}

TriangleMesh mesh(Engine& e) {
  return withoutGil(e.mutex, [&] { return e.engine.mesh(); }); // a copy: the engine keeps its own
}

/// The FrameSource `source` is, or a FrameList of the engine's rig made in `list` over a Python
/// sequence of Frame.
const FrameSource& sourceOf(const py::object& source, const Engine& e, std::optional<FrameList>& list) {
  if (py::isinstance<FrameSource>(source))
    return source.cast<const FrameSource&>();
  if (!py::hasattr(source, "__len__") || !py::hasattr(source, "__getitem__"))
    throw InvalidInputError("source must be a FrameSource (a Sequence, open_dataset's) or a sequence of Frame (a "
                            "list), not a " +
                            py::str(source.get_type().attr("__name__")).cast<std::string>());
  return list.emplace(source, e.engine.calibration());
}

/// Reconstructor::run on a thread of its own while this one, the caller's, waits without the GIL
/// and looks for signals every 0.1 s: Ctrl-C stops the run after the frame being integrated (as
/// msf_reconstruct does) and is raised once the run has ended. `on_frame` gets each FrameResult
/// on the engine's integration thread, with the GIL; it may call mesh() and num_blocks.
py::dict run(Engine& e, const py::object& frame_source, const std::optional<std::vector<long long>>& frames,
             const py::object& on_frame) {
  std::optional<FrameList> list;
  const FrameSource& source = sourceOf(frame_source, e, list);
  std::vector<std::size_t> indices(source.size());
  std::iota(indices.begin(), indices.end(), std::size_t(0));
  if (frames) { // indices as a Python sequence's: negative from the end
    indices.clear();
    for (const long long i : *frames)
      indices.push_back(frameIndex(source, i));
  }
  Reconstructor::FrameCallback callback;
  if (!on_frame.is_none())
    callback = [&](FrameResult& result) {
      py::gil_scoped_acquire gil;
      on_frame(std::move(result));
    };
  std::atomic<bool> stop{false};
  std::optional<py::error_already_set> interrupt;
  Reconstructor::RunStats stats;
  std::exception_ptr failure;
  {
    py::gil_scoped_release release;
    std::mutex done_mutex;
    std::condition_variable done_signal;
    bool done = false;
    std::thread runner([&] {
      try {
        std::lock_guard<std::recursive_mutex> engine_lock(e.mutex);
        stats = e.engine.run(source, indices, callback, &stop);
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(done_mutex);
      done = true;
      done_signal.notify_one();
    });
    std::unique_lock<std::mutex> lock(done_mutex);
    while (!done_signal.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; })) {
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        if (!interrupt && PyErr_CheckSignals() != 0) {
          interrupt.emplace(); // takes the raised error (KeyboardInterrupt) off the interpreter
          stop = true;
        }
      }
      lock.lock();
    }
    lock.unlock();
    runner.join();
  }
  if (interrupt)
    throw *interrupt;
  if (failure)
    std::rethrow_exception(failure);
  warnOfNewNotes(e);
  py::dict out;
  out["frames_done"] = stats.frames_done;
  out["wall_s"] = stats.wall_s;
  out["first_frame_s"] = stats.first_frame_s;
  out["interrupted"] = stats.interrupted;
  return out;
}

/// A property of FrameResult viewing one of its images.
template <cv::Mat FrameResult::*image>
py::object imageOf(const py::handle& self) {
  return viewOf(self.cast<const FrameResult&>().*image, self);
}

void bindFrameResult(py::module_& m) {
  py::class_<FrameResult>(m, "FrameResult",
                          "What one frame produced: depth images of camera 0, (H, W) float32 metres (0 = none), "
                          "each a view of the result (no copy), and the pose it was integrated at.")
      .def_property_readonly("index", [](const FrameResult& r) { return r.index; })
      .def_property_readonly("name", [](const FrameResult& r) { return r.name; })
      .def_property("pose", [](const FrameResult& r) -> py::object {
        return r.has_pose ? py::object(toArray(r.T_world_cam0)) : py::none();
      }, [](FrameResult& r, const ArrayArg& pose) {
        r.has_pose = !pose.is_none();
        r.T_world_cam0 = r.has_pose ? poseFrom(pose, "pose") : Eigen::Isometry3d::Identity();
      }, "T_world_cam0 (4x4): the frame's, or the odometry's after add_frame; settable before integrate().")
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
      .def_readonly("lidar_stereo_disagreement", &FrameResult::lidar_stereo_disagreement,
                    "Of the pixels with a real LiDAR return and a stereo depth, the share where the two differ by "
                    "more than 10 %: a few percent with a right rig, a large share with a wrong extrinsic, baseline "
                    "or unit; NaN where no pixel has both.")
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

void bindReconstructor(py::module_& m) {
  bindFrameResult(m);
  py::class_<Engine>(m, "Reconstructor",
                     "The engine: LiDAR completion and SGBM fused per pixel, each frame's pose (its own, or "
                     "LiDAR odometry's), the regularized TSDF volume and its mesh. The same classes and "
                     "settings as msf_reconstruct, so the same depth and mesh.")
      .def(py::init(&makeEngine), py::arg("calibration"), py::arg("config") = PipelineConfig(),
           py::arg("poses") = "auto", py::arg("threads") = 0, py::arg("stream_directory") = py::none(),
           "poses: auto (the frame's own pose; LiDAR odometry when the first frame has none), given (a frame "
           "without one is an error), odometry (always) or refine (the frames' own poses, a GPS/INS's, as the "
           "prior the LiDAR odometry refines). threads: of this engine's parallel loops, 0 = all "
           "cores. How the scans are taken is the rig's (calibration.lidar_sweeping). stream_directory: where "
           "a streamed map (streaming.active_radius_m > 0) writes its tiles. Raises ConfigError for an invalid "
           "config, CalibrationError for a rig without an image size.")
      .def("add_frame", &addFrame, py::arg("frame"),
           "A Frame's depth (steps 1-4), its pose and its integration into the map (step 5): its FrameResult, "
           "whose depth, weight and pose are the fused depth, its inverse variance and the pose used.")
      .def("compute_depth", &computeDepth, py::arg("frame"),
           "Steps 1-4 of a Frame, nothing added to the map. Raises InvalidInputError for images or a scan that "
           "do not fit the rig.")
      .def("integrate", &integrate, py::arg("result"),
           "Step 5: a compute_depth result at its pose into the map. Raises InvalidInputError without a pose, and "
           "for a result this map took already (add_frame's and run's too), which would weigh double.")
      .def("mesh", &mesh, "The map's Mesh, meshing again only the blocks changed since the last call.")
      .def("run", &run, py::arg("source"), py::arg("frames") = py::none(), py::arg("on_frame") = py::none(),
           "The frames of a source (a Sequence, open_dataset's, or a list of Frame made of your own arrays; "
           "all, or the indices given, negative from the end) overlapped on the engine's threads: the same map "
           "as add_frame frame by frame, faster. A list's Frame without an index is numbered by its place. "
           "on_frame(result) is called after each frame is integrated, in order; it may call mesh() and num_blocks (another call of the engine raises "
           "msfusion.Error). Ctrl-C stops after the frame being integrated and raises KeyboardInterrupt, the map "
           "holding the frames done. Returns frames_done, wall_s, first_frame_s and interrupted (a stop that was "
           "not Ctrl-C's).")
      .def_property_readonly("calibration", [](Engine& e) { return e.engine.calibration(); })
      .def_property_readonly("config", [](Engine& e) { return e.engine.config(); })
      .def_property_readonly("num_blocks", [](Engine& e) {
        return withoutGil(e.mutex, [&] { return e.engine.volume().numBlocks(); });
      }, "Blocks of 8^3 voxels the map holds.")
      .def_property_readonly("notes", [](Engine& e) { return e.engine.notes(); },
                             "What the engine did that you may not expect, a line each (each also raised once as a "
                             "UserWarning): poses='auto' tracking frames that have their own pose, since the first "
                             "had none.")
      .def_property_readonly("odometry_ms", [](Engine& e) { return e.engine.odometryMs(); },
                             "Milliseconds the odometry took for each frame it tracked.");
}

} // namespace msf::python
