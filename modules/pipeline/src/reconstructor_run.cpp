// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Reconstructor::run: the stages on their threads, joined by bounded queues.
#include <msf/common/elapsed.h>
#include <msf/common/parallel.h>
#include <msf/pipeline/bounded_queue.h>
#include <msf/pipeline/reconstructor.h>

#include "one_caller.h"

#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

namespace msf {

/// One run(): the queues between the stage threads, the first failure, and each stage's loop.
/// Loading (with steps 1-2 when SGBM waits for them), the odometry, stereo and fusion each have a
/// thread; integration runs on the caller's.
struct Reconstructor::Run {
  struct Loaded {
    Frame frame;
    FrameResult result;  // with the stereo prior or guidance, steps 1-2 are already done
    double load_ms;
  };

  Run(Reconstructor& engine, const FrameSource& source, const std::vector<std::size_t>& frames,
      const std::atomic<bool>* stop)
      : engine(engine), source(source), frames(frames), stop(stop),
        capacity(static_cast<std::size_t>(engine.config_.scheduling.queue_capacity)), loaded(capacity),
        depths(capacity), to_track(capacity), tracked(capacity),
        accumulating(engine.config_.accumulation.scans > 0) {}

  bool stopped() const { return stop && stop->load(); }

  /// Runs a stage's loop on its thread: its first exception stops the run.
  template <class Loop>
  void guarded(Loop loop) {
    const ThreadBudget budget(engine.options_.threads);
    try {
      loop();
    } catch (...) {
      fail(std::current_exception());
    }
  }

  void fail(std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure)
        failure = e;
    }
    closeAll();
  }

  void closeAll() {
    loaded.close();
    depths.close();
    to_track.close();
    tracked.close();
  }

  /// The loader: each frame loaded and filtered, its pose on its way (tracked here when the earlier
  /// scans need it before steps 1-2, else queued for the odometry), steps 1-2 when SGBM waits for
  /// them.
  void loadFrames() {
    for (std::size_t i : frames) {
      if (stopped()) {
        interrupted = true;
        break;
      }
      Loaded item = load(i);
      if (!sendToTracking(item))
        break;
      if (engine.lidarBeforeStereo()) // one frame ahead of SGBM
        engine.computeLidar(item.frame, item.result);
      if (!loaded.push(std::move(item)))
        break;
    }
  }

  Loaded load(std::size_t i) {
    const auto start = Clock::now();
    Loaded item{source.load(i), FrameResult(), 0.0};
    if (Frame whole; &withWholeImages(item.frame, whole) == &whole)
      item.frame = std::move(whole);
    if (engine.frame_filter_)
      engine.frame_filter_(item.frame);
    checkFrame(item.frame, engine.calibration_);
    engine.checkTimeOrder(item.frame);
    item.load_ms = msSince(start);
    if (i == frames.front())
      tracking = engine.tracks(item.frame);
    item.result = engine.startFrame(item.frame);
    return item;
  }

  /// False when the run has stopped.
  bool sendToTracking(Loaded& item) {
    if (!tracking)
      return true;
    if (accumulating) { // steps 1-2 place the earlier scans by this frame's pose: tracked first
      item.result.T_world_cam0 = engine.track(item.frame, source.scanName(item.frame.index));
      item.result.has_pose = true;
      return tracked.push(item.result.T_world_cam0);
    }
    Frame scan_only;
    scan_only.index = item.frame.index;
    scan_only.timestamp = item.frame.timestamp;
    scan_only.scan = item.frame.scan;         // shared, read only: no stage changes a scan after the filter
    scan_only.has_pose = item.frame.has_pose; // the first frame's anchors the odometry's world
    scan_only.T_world_cam0 = item.frame.T_world_cam0;
    return to_track.push(std::move(scan_only));
  }

  /// The odometry's thread: the poses of the queued scans, in frame order.
  void trackScans() {
    while (auto frame = to_track.pop())
      if (!tracked.push(engine.track(*frame, source.scanName(frame->index))))
        break;
  }

  /// The depth thread: steps 3-4 (and 1-2 when they run beside SGBM) of each loaded frame.
  void computeDepths() {
    while (auto item = loaded.pop()) {
      if (stopped())
        break; // a frame not started is dropped: a stop should be prompt
      FrameResult result = std::move(item->result);
      if (engine.lidarBeforeStereo()) {
        const auto start = Clock::now();
        engine.computeStereo(item->frame, result);
        result.times.depth_ms = msSince(start) + result.times.lidar_ms;
        engine.computeFusion(item->frame, result);
        engine.computeSky(result);
      } else {
        engine.computeDepth(item->frame, result);
      }
      result.name = source.frameName(item->frame.index);
      result.times.load_ms = item->load_ms;
      if (!depths.push(std::move(result)))
        break;
    }
  }

  /// The caller's thread: each frame's pose, its integration (step 5), the mesh every n frames and
  /// the callback, in frame order.
  RunStats integrateFrames(const FrameCallback& on_frame) {
    RunStats stats;
    while (auto result = depths.pop()) {
      if (tracking) {
        auto pose = tracked.pop();
        if (!pose)
          break; // the estimator failed (its error is rethrown by run) or the run stopped
        result->T_world_cam0 = *pose;
        result->has_pose = true;
      }
      engine.integrateResult(*result);
      const int mesh_every = engine.config_.scheduling.mesh_every_n_frames;
      if (mesh_every > 0 && (stats.frames_done + 1) % static_cast<std::size_t>(mesh_every) == 0)
        engine.remesh();
      ++stats.frames_done;
      if (on_frame)
        on_frame(*result);
      if (stats.frames_done == 1)
        stats.first_frame_s = msSince(start) / 1000.0;
      if (stopped()) {
        interrupted = stats.frames_done < frames.size();
        break;
      }
    }
    return stats;
  }

  using Clock = std::chrono::steady_clock;
  Reconstructor& engine;
  const FrameSource& source;
  const std::vector<std::size_t>& frames;
  const std::atomic<bool>* stop;
  const std::size_t capacity;
  BoundedQueue<Loaded> loaded;
  BoundedQueue<FrameResult> depths;
  BoundedQueue<Frame> to_track;                // scans for the odometry
  BoundedQueue<Eigen::Isometry3d> tracked;     // its poses, in frame order
  // Set by the loader from the first frame before any frame moves on: read after a queue's pop.
  std::atomic<bool> tracking{false};
  std::atomic<bool> interrupted{false};
  const bool accumulating;
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const Clock::time_point start = Clock::now();
};

Reconstructor::RunStats Reconstructor::run(const FrameSource& source, const std::vector<std::size_t>& frames,
                                           const FrameCallback& on_frame, const std::atomic<bool>* stop) {
  const OneCaller call(caller_, "run");
  Run r(*this, source, frames, stop);
  std::thread loader([&] {
    r.guarded([&] { r.loadFrames(); });
    r.loaded.close();
    r.to_track.close();
  });
  std::thread tracker([&] {
    r.guarded([&] { r.trackScans(); });
    r.tracked.close();
  });
  std::thread depth([&] {
    r.guarded([&] { r.computeDepths(); });
    r.depths.close();
  });
  RunStats stats;
  r.guarded([&] { stats = r.integrateFrames(on_frame); });
  r.closeAll(); // wakes the other stages when the loop ended early
  loader.join();
  depth.join();
  tracker.join();
  if (r.failure)
    std::rethrow_exception(r.failure);
  stats.wall_s = msSince(r.start) / 1000.0;
  stats.interrupted = r.interrupted;
  return stats;
}

} // namespace msf
