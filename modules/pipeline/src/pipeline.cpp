#include <msf/common/exceptions.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/io/pinhole_camera.h>
#include <msf/pipeline/bounded_queue.h>
#include <msf/pipeline/pipeline.h>
#include <msf/pipeline/source_depth_frame.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/real_returns.h>
#include <msf/stereo/color_sampler.h>
#include <msf/stereo/sgbm_stereo.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <future>
#include <mutex>
#include <optional>
#include <thread>

namespace msf {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
} // namespace

/// The stage objects of steps 1-4, configured once; they keep their work buffers.
struct Pipeline::Stages {
  explicit Stages(const Calibration& calibration, const PipelineConfig& config)
      : lidar(calibration, CompletionMethod::Compound, config.projection, config.interpolation) {}
  LidarCompletion lidar;  // projection onto the canvas with its margin, then interpolation
  SgbmStereo stereo;
  DepthImageFusion fusion;
};

Pipeline::Pipeline(const Calibration& calibration, const PipelineConfig& config)
    : calibration_(calibration), config_(config), mesher_(config.mesher) {
  config_.validate();
  calibration_.requireImageSize();
  stages_ = std::make_unique<Stages>(calibration_, config_);
  volume_ = std::make_unique<TsdfVolume>(config_.volume.voxel_size_m, config_.volume.truncation_m);
  volume_->setMaxMemoryMb(config_.volume.max_memory_mb);
  integrator_ = std::make_unique<TsdfIntegrator>(*volume_, config_.integrator);

  stages_->stereo.setConfig(config_.stereo);
  stages_->stereo.setCalibration(calibration_);
  stages_->fusion.setConfig(config_.fusion);
  stages_->fusion.setCalibration(calibration_);
  camera_ = PinholeCamera::fromCalibration(calibration_, config_.projection.camera);
}

Pipeline::~Pipeline() = default;

FrameResult Pipeline::startFrame(const Frame& frame) const {
  FrameResult result;
  result.index = frame.index;
  result.has_pose = frame.has_pose;
  result.T_world_cam0 = frame.T_world_cam0;
  result.left = frame.left;
  return result;
}

void Pipeline::computeLidar(const Frame& frame, FrameResult& result) {
  const auto start = Clock::now();
  stages_->lidar.computeDepth(*frame.scan, result.lidar_depth, &result.lidar_distance);
  stages_->lidar.canvasDepth().copyTo(result.lidar_canvas_depth); // its buffers serve the next scan
  stages_->lidar.canvasDistance().copyTo(result.lidar_canvas_distance);
  result.lidar_canvas_camera = stages_->lidar.projector().canvasCamera();
  if (config_.integrator.scan_carving_m > 0.0 && config_.integrator.space_carving)
    result.scan_free_space = ScanFreeSpace(*frame.scan);
  result.times.lidar_ms = msSince(start);
  if (keep_sparse_)
    stages_->lidar.projector().projectToImage(*frame.scan, result.lidar_sparse);
}

void Pipeline::computeStereo(const Frame& frame, FrameResult& result) {
  const auto start = Clock::now();
  stages_->stereo.setInputImages(frame.left, frame.right);
  // With the prior, SGBM searches only the disparities the interpolated LiDAR allows; guided,
  // the real returns among it steer the matching.
  stages_->stereo.setDepthPrior(config_.scheduling.stereo_prior ? result.lidar_depth : cv::Mat());
  stages_->stereo.setGuidance(config_.stereo.lidarGuidance() ? realReturns(result.lidar_depth, result.lidar_distance)
                                                             : cv::Mat());
  stages_->stereo.computeDisparity();
  result.stereo_depth = stages_->stereo.getDepth();
  result.stereo_confidence = stages_->stereo.getConfidence(); // a new image each frame
  result.times.stereo_ms = msSince(start);
}

void Pipeline::computeFusion(const Frame& frame, FrameResult& result) {
  const auto start = Clock::now();
  DepthFrame& fused = result.fused;
  stages_->fusion.fuse(result.lidar_depth, result.lidar_distance, result.stereo_depth, result.stereo_confidence,
                       fused.depth, &fused.weight, &fused.free_space_weight);
  // Colour from the colour camera at the fused point, also where only the LiDAR has depth.
  fused.camera = camera_;
  const ColorSampler sampler = frame.color.empty()
                                   ? ColorSampler()
                                   : ColorSampler(frame.color, calibration_, config_.stereo.color_camera);
  colorizeDepth(fused.depth, camera_, sampler, frame.left, fused.color);
  result.times.fusion_ms = msSince(start);
}

bool Pipeline::lidarBeforeStereo() const {
  return config_.scheduling.stereo_prior || config_.stereo.lidarGuidance();
}

FrameResult Pipeline::computeDepth(const Frame& frame) {
  FrameResult result = startFrame(frame);
  const auto depth_start = Clock::now();
  if (lidarBeforeStereo()) {
    computeLidar(frame, result);
    computeStereo(frame, result);
  } else {
    // Steps 1-2 on their own thread while SGBM (step 3) runs here: they share no state.
    auto lidar = std::async(std::launch::async, [&] { computeLidar(frame, result); });
    try {
      computeStereo(frame, result);
    } catch (...) {
      lidar.wait(); // never leave the other thread writing into `result`
      throw;
    }
    lidar.get();
  }
  result.times.depth_ms = msSince(depth_start);
  computeFusion(frame, result);
  return result;
}

void carveWithScan(TsdfIntegrator& integrator, const FrameResult& result, const PinholeCamera& camera,
                   const DepthFusionConfig& fusion, const Calibration& calibration) {
  if (!integrator.getConfig().space_carving || result.scan_free_space.empty())
    return;
  const double sigma = fusion.lidar_range_sigma_m;
  integrator.carveWithScan(result.scan_free_space, result.T_world_cam0 * calibration.T_cam0_velo,
                           static_cast<float>(1.0 / (sigma * sigma)), camera, result.T_world_cam0);
}

void Pipeline::integrate(FrameResult& result) {
  if (!result.has_pose)
    throw InvalidInputError("frame " + (result.name.empty() ? std::to_string(result.index) : result.name) +
                            " has no pose: integration needs the sequence's poses");
  const auto start = Clock::now();
  if (streaming_)
    streaming_->beforeIntegration(result.T_world_cam0.translation());
  const DepthFrame frame = fusedDepthFrame(result, config_.fusion, calibration_.focalBaseline());
  integrator_->integrate(frame, result.T_world_cam0);
  carveWithScan(*integrator_, result, frame.camera, config_.fusion, calibration_);
  if (streaming_) {
    const std::size_t freed = streaming_->stats().blocks_freed;
    streaming_->afterIntegration(result.T_world_cam0.translation());
    if (streaming_->stats().blocks_freed != freed)
      mesher_.reset(); // its cache holds the freed blocks' meshes
  }
  result.times.integrate_ms = msSince(start);
}

void Pipeline::setStreamingDirectory(const std::string& directory) {
  if (!config_.streaming.enabled())
    throw ConfigError("streaming.active_radius_m is 0: the map is not streamed, no folder is needed");
  // How far from the camera integration changes blocks that exist, over the LiDAR's canvas
  // (the image and its margin: the frames integrated are at most that).
  const double reach = integrator_->reach(stages_->lidar.projector().canvasCamera());
  if (!std::isfinite(reach))
    throw ConfigError("a streamed map needs a bound on the band behind a surface: tsdf_integrator.min_pixel_weight > 0 "
                      "or truncation_sigmas 0 (with per-pixel weights the band grows as a pixel's weight falls)");
  streaming_ = std::make_unique<StreamingMap>(*volume_, config_.streaming, config_.mesher, reach, directory);
}

std::size_t Pipeline::finishStreaming(const std::string& mesh_path) {
  if (!streaming_)
    throw ConfigError("finishStreaming: the map is not streamed (setStreamingDirectory)");
  mesher_.reset();
  return streaming_->finish(mesh_path);
}

Pipeline::RunStats Pipeline::run(const Sequence& sequence, const std::vector<std::size_t>& frames,
                                 const FrameCallback& on_frame, const std::atomic<bool>* stop) {
  struct Loaded {
    Frame frame;
    FrameResult result;  // with the stereo prior or guidance, steps 1-2 are already done
    double load_ms;
  };
  const auto capacity = static_cast<std::size_t>(config_.scheduling.queue_capacity);
  BoundedQueue<Loaded> loaded(capacity);
  BoundedQueue<FrameResult> depths(capacity);
  BoundedQueue<Frame> to_track(capacity);            // scans for the pose estimator
  BoundedQueue<Eigen::Isometry3d> tracked(capacity);  // its poses, in frame order
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto fail = [&](std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure)
        failure = e;
    }
    loaded.close();
    depths.close();
    to_track.close();
    tracked.close();
  };
  std::atomic<bool> interrupted{false};

  const auto run_start = Clock::now();
  std::thread loader([&] {
    try {
      for (std::size_t i : frames) {
        if (stop && stop->load()) {
          interrupted = true;
          break;
        }
        const auto start = Clock::now();
        Loaded item{sequence.load(i), FrameResult(), 0.0};
        if (frame_filter_)
          frame_filter_(item.frame);
        item.load_ms = msSince(start);
        if (pose_estimator_) {
          Frame scan_only;
          scan_only.index = item.frame.index;
          scan_only.timestamp = item.frame.timestamp;
          scan_only.scan = item.frame.scan; // shared, read only: no stage changes a scan after the filter
          if (!to_track.push(std::move(scan_only)))
            break;
        }
        item.result = startFrame(item.frame);
        // Steps 1-2 here, one frame ahead of SGBM, when SGBM waits for their prior or guidance.
        if (lidarBeforeStereo())
          computeLidar(item.frame, item.result);
        if (!loaded.push(std::move(item)))
          break;
      }
    } catch (...) {
      fail(std::current_exception());
    }
    loaded.close();
    to_track.close();
  });
  std::thread tracker;
  if (pose_estimator_)
    tracker = std::thread([&] {
      try {
        while (auto frame = to_track.pop())
          if (!tracked.push(pose_estimator_(*frame)))
            break;
      } catch (...) {
        fail(std::current_exception());
      }
      tracked.close();
    });
  std::thread depth([&] {
    try {
      while (auto item = loaded.pop()) {
        if (stop && stop->load())
          break; // a frame not started is dropped: a stop should be prompt
        FrameResult result;
        if (lidarBeforeStereo()) {
          result = std::move(item->result);
          const auto start = Clock::now();
          computeStereo(item->frame, result);
          result.times.depth_ms = msSince(start) + result.times.lidar_ms;
          computeFusion(item->frame, result);
        } else {
          result = computeDepth(item->frame);
        }
        result.name = sequence.frameName(item->frame.index);
        result.times.load_ms = item->load_ms;
        if (!depths.push(std::move(result)))
          break;
      }
    } catch (...) {
      fail(std::current_exception());
    }
    depths.close();
  });

  if (config_.streaming.enabled() && !streaming_)
    throw ConfigError("streaming.active_radius_m > 0 needs a folder for the tiles: Pipeline::setStreamingDirectory");
  RunStats stats;
  try {
    while (auto result = depths.pop()) {
      if (pose_estimator_) {
        auto pose = tracked.pop();
        if (!pose)
          break; // the estimator failed (its error is rethrown below) or the run stopped
        result->T_world_cam0 = *pose;
        result->has_pose = true;
      }
      integrate(*result);
      if (config_.scheduling.mesh_every_n_frames > 0 &&
          (stats.frames_done + 1) % static_cast<std::size_t>(config_.scheduling.mesh_every_n_frames) == 0)
        updateMesh();
      ++stats.frames_done;
      if (on_frame)
        on_frame(*result);
      if (stats.frames_done == 1)
        stats.first_frame_s = msSince(run_start) / 1000.0;
      if (stop && stop->load()) {
        interrupted = stats.frames_done < frames.size();
        break;
      }
    }
  } catch (...) {
    fail(std::current_exception());
  }
  loaded.close(); // wakes the other stages when the loop ended early
  depths.close();
  to_track.close();
  tracked.close();
  loader.join();
  depth.join();
  if (tracker.joinable())
    tracker.join();
  if (failure)
    std::rethrow_exception(failure);
  stats.wall_s = msSince(run_start) / 1000.0;
  stats.interrupted = interrupted;
  return stats;
}

const TriangleMesh& Pipeline::updateMesh() {
  mesher_.extract(*volume_, mesh_);
  return mesh_;
}

} // namespace msf
