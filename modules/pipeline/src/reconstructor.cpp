// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/elapsed.h>
#include <msf/common/exceptions.h>
#include <msf/common/parallel.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/hole_fill.h>
#include <msf/io/pinhole_camera.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/rig_agreement.h>
#include <msf/pipeline/run_report.h>
#include <msf/pipeline/source_depth_frame.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/real_returns.h>
#include <msf/range_image/scan_history.h>
#include <msf/reconstruction/block_footprint.h>
#include <msf/reconstruction/scan_band_blocks.h>
#include <msf/stereo/color_sampler.h>
#include <msf/stereo/sgbm_stereo.h>

#include "one_caller.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <future>
#include <optional>
#include <sstream>

namespace msf {

namespace {
using Clock = std::chrono::steady_clock;
// The memory model of predictMemory beside the TSDF volume, from msf_reconstruct's RSS per frame
// (frames.csv) and peak (summary.json) on KITTI and the synthetic street (docs/robustness.md,
// "Memory budget"; the figures in docs/results.md).
// The stages' own buffers (SGBM's strips, the LiDAR canvas, fusion), per pixel of the canvas,
// and the heap the calibration frames' buffers leave behind: above the most measured on a run of
// one frame, where this term is most of the peak, by the peak's spread from run to run.
constexpr double kStageBytesPerPixel = 370;
// A frame in flight (images, scan, depth images).
constexpr double kFrameBytesPerPixel = 24;
// A pixel whose ground truth the run keeps to score the mesh at the end (protocol 4): its index
// and its depth (the estimates waiting for later scans to mark them are a few frames' only).
constexpr double kScoredBytesPerPixel = 8;
// What the end of an in-memory run adds (the mesh, its per-block cache, the copy written and
// volume.pcd's compressed pieces), in units of the predicted volume's bytes: above the most
// measured in units of the real volume's, since the predicted volume can be as little as the real one.
constexpr double kEndOfRunShare = 2.0;
// A streamed run's tiles meshed as they leave, in units of the window's volume bytes.
constexpr double kStreamedEndShare = 1.0;
// A map of one source alone or of the paper's method (-compare_sources, -compare_paper), its
// mesh included, in units of the fused map's volume bytes.
constexpr double kOtherMapShare = 1.6;
// The blocks the scans' bands predict, grown against the spread of the measured share between
// frames (the calibration frames are a few of the run's).
constexpr double kBlockMargin = 1.15;
// Frames integrated to measure the share of the fused depth's blocks in the scans' bands.
constexpr int kCalibrationFrames = 3;
} // namespace

/// The stage objects of steps 1-4, configured once; they keep their work buffers.
struct Reconstructor::Stages {
  explicit Stages(const Calibration& calibration, const PipelineConfig& config)
      : lidar(calibration, CompletionMethod::Compound, config.projection, config.interpolation),
        history(calibration, config.projection, config.accumulation) {}
  LidarCompletion lidar;  // projection onto the canvas with its margin, then interpolation
  ScanHistory history;    // the earlier scans that step 1 carries into the view
  SgbmStereo stereo;
  DepthImageFusion fusion;
};

Reconstructor::Reconstructor(const Calibration& rig, const PipelineConfig& config)
    : Reconstructor(rig, config, Options()) {}

Reconstructor::Reconstructor(const Calibration& rig, const PipelineConfig& config, const Options& options)
    : calibration_(rig), config_(adaptToRig(config, rig)), options_(options), mesher_(config.mesher) {
  config_.validate();
  calibration_.validate();
  calibration_.requireImageSize();
  if (options_.threads < 0)
    throw ConfigError("Reconstructor: threads must be >= 0 (0: all cores), got " + std::to_string(options_.threads));
  const ThreadBudget budget(options_.threads);
  stages_ = std::make_unique<Stages>(calibration_, config_);
  volume_ = std::make_unique<TsdfVolume>(config_.volume.voxel_size_m, config_.volume.truncation_m);
  volume_->setMaxMemoryMb(config_.volume.max_memory_mb);
  integrator_ = std::make_unique<TsdfIntegrator>(*volume_, config_.integrator);

  stages_->stereo.setConfig(config_.stereo);
  stages_->stereo.setCalibration(calibration_);
  stages_->fusion.setConfig(config_.fusion);
  stages_->fusion.setCalibration(calibration_);
  camera_ = PinholeCamera::fromCalibration(calibration_, config_.projection.camera);
  startStreaming();
}

Reconstructor::~Reconstructor() = default;

const ScanHistory& Reconstructor::scanHistory() const { return stages_->history; }

namespace {
std::uint64_t newSerial() {
  static std::atomic<std::uint64_t> last{0};
  return ++last;
}
} // namespace

FrameResult Reconstructor::startFrame(const Frame& frame) const {
  FrameResult result;
  result.serial = newSerial();
  result.index = frame.index;
  result.has_pose = frame.has_pose;
  result.T_world_cam0 = frame.T_world_cam0;
  result.left = frame.left;
  return result;
}

void Reconstructor::computeLidar(const Frame& frame, FrameResult& result) {
  const auto start = Clock::now();
  const Eigen::Isometry3d T_world_velo = result.T_world_cam0 * calibration_.T_cam0_velo;
  const auto& scan = stages_->history.withEarlierScans(*frame.scan, result.has_pose ? &T_world_velo : nullptr);
  stages_->lidar.computeDepth(scan, result.lidar_depth, &result.lidar_distance);
  if (cv::countNonZero(result.lidar_depth) == 0) // with a right rig, a LiDAR always sees what is ahead
    throw InvalidInputError("frame " + std::to_string(frame.index) + ": no return of its scan (" +
                            std::to_string(frame.scan->size()) + " points) lands in camera 0 within " +
                            "projection.max_range_m: is the rig's LiDAR extrinsic the LiDAR-to-camera transform "
                            "(not its inverse), and are the scan's units metres?");
  stages_->lidar.canvasDepth().copyTo(result.lidar_canvas_depth); // its buffers serve the next scan
  stages_->lidar.canvasDistance().copyTo(result.lidar_canvas_distance);
  result.lidar_canvas_camera = stages_->lidar.projector().canvasCamera();
  if (integrator_->carvesWithScans()) // built here, beside SGBM, rather than on the map's thread
    result.scan_free_space = ScanFreeSpace(*frame.scan, calibration_.lidar.sweeping);
  result.times.lidar_ms = msSince(start);
  if (options_.keep_sparse)
    stages_->lidar.projector().projectToImage(*frame.scan, result.lidar_sparse);
}

void Reconstructor::computeStereo(const Frame& frame, FrameResult& result) {
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



void Reconstructor::computeFusion(const Frame& frame, FrameResult& result) {
  const auto start = Clock::now();
  DepthFrame& fused = result.fused;
  stages_->fusion.setInputImage(frame.left); // for the facade extension
  stages_->fusion.setSkyImage(skyImage(frame.color, frame.left, frame.left.size()));
  stages_->fusion.fuse(result.lidar_depth, result.lidar_distance, result.stereo_depth, result.stereo_confidence,
                       fused.depth, &fused.weight, &fused.free_space_weight);
  // Colour from the colour camera at the fused point, also where only the LiDAR has depth.
  fused.camera = camera_;
  const ColorSampler sampler = frame.color.empty()
                                   ? ColorSampler()
                                   : ColorSampler(frame.color, calibration_, config_.stereo.color_camera);
  colorizeDepth(fused.depth, camera_, sampler, frame.left, fused.color);
  result.lidar_stereo_disagreement =
      lidarStereoDisagreement(result.lidar_depth, result.lidar_distance, result.stereo_depth);
  result.times.fusion_ms = msSince(start);
}

void Reconstructor::computeSky(FrameResult& result) {
  stages_->fusion.findOpenSky(result.sky, result.sky_depth);
}

bool Reconstructor::lidarBeforeStereo() const {
  return config_.scheduling.stereo_prior || config_.stereo.lidarGuidance();
}

FrameResult Reconstructor::computeDepth(const Frame& given) {
  const OneCaller call(caller_, "computeDepth");
  return depthOf(given);
}

FrameResult Reconstructor::depthOf(const Frame& given) {
  Frame copy;
  const Frame& frame = withWholeImages(given, copy);
  checkFrame(frame, calibration_);
  const ThreadBudget budget(options_.threads);
  FrameResult result = startFrame(frame);
  computeDepth(frame, result);
  return result;
}

void Reconstructor::computeDepth(const Frame& frame, FrameResult& result) {
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
  computeSky(result);
}

TsdfIntegrator::FreeSpace freeSpaceOf(const FrameResult& result, const PinholeCamera& sky_camera,
                                      const DepthFusionConfig& fusion, const Calibration& calibration,
                                      bool with_scan) {
  TsdfIntegrator::FreeSpace free;
  free.weight = fusion.lidarRangeWeight();
  if (with_scan && !result.scan_free_space.empty()) {
    free.scan = &result.scan_free_space;
    free.T_world_lidar = result.T_world_cam0 * calibration.T_cam0_velo;
  }
  free.sky_depth = result.sky_depth;
  free.sky_camera = sky_camera;
  return free;
}

void Reconstructor::integrate(FrameResult& result) {
  const OneCaller call(caller_, "integrate");
  integrateResult(result);
}

void Reconstructor::integrateResult(FrameResult& result) {
  const std::string frame_name = result.name.empty() ? std::to_string(result.index) : result.name;
  if (!result.has_pose)
    throw InvalidInputError("frame " + frame_name + " has no pose: integration needs one (the frame's, or PoseMode "
                            "Odometry)");
  const PinholeCamera& made_by = result.fused.camera;
  if (made_by.valid() && made_by != camera_)
    throw InvalidInputError("frame " + frame_name + "'s result was computed for a camera of " +
                            made_by.intrinsicsText() + ", " + std::to_string(made_by.width) + "x" +
                            std::to_string(made_by.height) + ", not this map's rig (" + camera_.intrinsicsText() +
                            "): integrate it into an engine of its own rig");
  if (result.serial == 0)
    result.serial = newSerial();
  if (integrated_.count(result.serial) != 0)
    throw InvalidInputError("frame " + frame_name + "'s result is in the map already (addFrame and run integrate "
                            "theirs): a second time would double its weight");
  if (config_.streaming.enabled() && !streaming_)
    throw ConfigError("streaming.active_radius_m > 0 needs a folder for the tiles (Options::stream_directory)");
  const ThreadBudget budget(options_.threads);
  const auto start = Clock::now();
  if (streaming_)
    streaming_->beforeIntegration(result.T_world_cam0.translation());
  const DepthFrame frame = fusedDepthFrame(result, config_.fusion, calibration_.focalBaseline());
  fillHoles(result);
  integrator_->integrateFrame(frame, result.T_world_cam0, freeSpaceOf(result, camera_, config_.fusion, calibration_));
  if (streaming_) {
    const std::size_t freed = streaming_->stats().blocks_freed;
    streaming_->afterIntegration(result.T_world_cam0.translation());
    if (streaming_->stats().blocks_freed != freed)
      mesher_.reset(); // its cache holds the freed blocks' meshes
  }
  integrated_.insert(result.serial);
  result.times.integrate_ms = msSince(start);
}

cv::Mat mapPriorHoles(const FrameResult& result) {
  cv::Mat holes = ~(result.fused.depth > 0.f); // no depth (0 or NaN)
  if (!result.sky.empty())
    holes.setTo(0, result.sky);
  return holes;
}

void Reconstructor::fillHoles(FrameResult& result) const {
  DepthFrame& fused = result.fused;
  const bool from_map = config_.map_prior.enabled && volume_->numBlocks() > 0 && !fused.weight.empty();
  const bool small = config_.fusion.hole_fill_px > 0 && !fused.depth.empty();
  if (!from_map && !small)
    return;
  // New images: the frame being integrated shares the fused ones.
  fused.depth = fused.depth.clone();
  if (!fused.weight.empty())
    fused.weight = fused.weight.clone();
  if (!fused.free_space_weight.empty())
    fused.free_space_weight = fused.free_space_weight.clone();
  if (from_map)
    fillFromMap(result);
  if (small)
    msf::fillSmallHoles(fused.depth, fused.weight, fused.free_space_weight, result.sky, config_.fusion.hole_fill_px);
}

void Reconstructor::fillFromMap(FrameResult& result) const {
  DepthFrame& fused = result.fused;
  cv::Mat depth, weight;
  MapRaycaster(*volume_, config_.map_prior)
      .render(fused.camera, result.T_world_cam0, mapPriorHoles(result), depth, weight);
  const cv::Mat found = depth > 0.f;
  depth.copyTo(fused.depth, found);
  weight.copyTo(fused.weight, found);
  if (!fused.free_space_weight.empty())
    fused.free_space_weight.setTo(0.f, found);
}

bool Reconstructor::tracks(const Frame& first) const {
  switch (options_.poses) {
  case PoseMode::Given:
    return false;
  case PoseMode::Odometry:
  case PoseMode::Refine:
    return true;
  case PoseMode::Auto:
    break;
  }
  return !first.has_pose;
}

Eigen::Isometry3d Reconstructor::track(const Frame& frame, const std::string& scan_name) {
  // Refused before the odometry takes the frame in: a retry would find it changed.
  if (!frame.scan)
    throw InvalidInputError("frame " + std::to_string(frame.index) + " has no scan to track");
  if (options_.poses == PoseMode::Refine && !frame.has_pose)
    throw InvalidInputError("frame " + std::to_string(frame.index) +
                            " has no pose to refine (PoseMode Refine refines each frame's own pose with its scan)");
  if (!odometry_) {
    LidarOdometry::Config odometry = config_.odometry;
    if (odometry.deskew == "auto")
      odometry.deskew = calibration_.lidar.sweeping ? "sweep" : "none";
    odometry_ = std::make_unique<LidarOdometry>(odometry);
    T_world_cam0_first_ = frame.has_pose ? frame.T_world_cam0 : Eigen::Isometry3d::Identity();
  }
  if (options_.poses == PoseMode::Auto && frame.has_pose && !poses_not_used_) {
    poses_not_used_ = true;
    say("frames with their own pose, from frame " + std::to_string(frame.index) +
        " on, were tracked by LiDAR odometry instead: the first frame had none, so PoseMode Auto tracks every frame; "
        "give the first frame its pose, or use PoseMode Refine to refine the poses with the scans");
  }
  const auto start = Clock::now();
  const std::optional<Eigen::Isometry3d> measured = measuredMotion(frame);
  const Eigen::Isometry3d T_velo0_velo =
      odometry_->registerScan(*frame.scan, scan_name, measured ? &*measured : nullptr);
  odometry_ms_.push_back(msSince(start));
  return cameraPose(T_velo0_velo, calibration_.T_cam0_velo, T_world_cam0_first_);
}

void Reconstructor::checkTimeOrder(const Frame& frame) {
  if (last_time_s_ && frame.timestamp < *last_time_s_ && !time_went_back_) {
    time_went_back_ = true;
    std::ostringstream note;
    note << "frame " << frame.index << " (at " << frame.timestamp << " s) came after a frame at " << *last_time_s_
         << " s: the frames are not in time order, which the odometry's prediction of each scan's motion and the "
            "earlier scans (accumulation) assume; give them in the order of Frame::timestamp";
    say(note.str());
  }
  last_time_s_ = frame.timestamp;
}

void Reconstructor::say(std::string note) {
  const std::lock_guard<std::mutex> lock(notes_mutex_);
  notes_.push_back(std::move(note));
}

std::vector<std::string> Reconstructor::notes() const {
  const std::lock_guard<std::mutex> lock(notes_mutex_);
  return notes_;
}

std::optional<Eigen::Isometry3d> Reconstructor::measuredMotion(const Frame& frame) {
  if (options_.poses != PoseMode::Refine)
    return std::nullopt;
  const Eigen::Isometry3d T_world_velo = frame.T_world_cam0 * calibration_.T_cam0_velo;
  if (odometry_->poses().empty()) // the first scan is the odometry's origin: any motion marks it as measured
    T_world_velo_measured_last_ = T_world_velo;
  const Eigen::Isometry3d motion = T_world_velo_measured_last_.inverse() * T_world_velo;
  T_world_velo_measured_last_ = T_world_velo;
  return motion;
}

FrameResult Reconstructor::addFrame(const Frame& given) {
  const OneCaller call(caller_, "addFrame");
  Frame copy;
  const Frame& frame = withWholeImages(given, copy);
  checkFrame(frame, calibration_); // before the odometry or the earlier scans take it in
  if (frame.scan && last_scan_.lock() == frame.scan)
    throw InvalidInputError("frame " + std::to_string(frame.index) +
                            " is the frame given last (the same scan): given twice, the map would take it twice");
  const ThreadBudget budget(options_.threads);
  if (frames_added_ == 0)
    add_tracks_ = tracks(frame);
  FrameResult result = startFrame(frame);
  if (add_tracks_) { // first: steps 1-2 place the earlier scans by the frame's pose
    result.T_world_cam0 = track(frame, "the scan of frame " + std::to_string(frame.index));
    result.has_pose = true;
  }
  computeDepth(frame, result);
  integrateResult(result);
  last_scan_ = frame.scan;
  checkTimeOrder(frame); // once taken: a refused frame can be given again
  ++frames_added_;
  if (config_.scheduling.mesh_every_n_frames > 0 &&
      frames_added_ % static_cast<std::size_t>(config_.scheduling.mesh_every_n_frames) == 0)
    remesh();
  return result;
}

void Reconstructor::startStreaming() {
  if (!config_.streaming.enabled()) {
    if (!options_.stream_directory.empty())
      throw ConfigError("a folder for the streamed map was given, but streaming.active_radius_m is 0: the map "
                        "stays in memory");
    return;
  }
  if (options_.stream_directory.empty())
    return; // integrate() refuses to run without it; predictMemory() needs none
  // How far from the camera integration changes blocks that exist, over the LiDAR's canvas
  // (the image and its margin: the frames integrated are at most that).
  const double reach = integrator_->reach(stages_->lidar.projector().canvasCamera());
  if (!std::isfinite(reach))
    throw ConfigError("a streamed map needs a bound on the band behind a surface: tsdf_integrator.min_pixel_weight > 0 "
                      "or truncation_sigmas 0 (with per-pixel weights the band grows as a pixel's weight falls)");
  streaming_ = std::make_unique<StreamingMap>(*volume_, config_.streaming, config_.mesher, reach,
                                              options_.stream_directory);
}

double Reconstructor::minimumStreamingRadius() const {
  return integrator_->reach(stages_->lidar.projector().canvasCamera()) +
         config_.streaming.tile_blocks * TsdfBlock::kSide * config_.volume.voxel_size_m;
}

std::size_t Reconstructor::finishStreaming(const std::string& mesh_path) {
  const OneCaller call(caller_, "finishStreaming");
  if (!streaming_)
    throw ConfigError("finishStreaming: the map is not streamed (Options::stream_directory)");
  const ThreadBudget budget(options_.threads);
  mesher_.reset();
  return streaming_->finish(mesh_path);
}

std::string MemoryPrediction::describe() const {
  char blocks_text[256];
  if (blocks_per_band_block > 0.0 && blocks < footprint_blocks)
    std::snprintf(blocks_text, sizeof blocks_text, "%zu blocks%s (%zu within the scans' bands x %.2f measured)",
                  blocks_in_memory, blocks_in_memory == blocks ? "" : " in memory at once", band_blocks,
                  blocks_per_band_block);
  else
    std::snprintf(blocks_text, sizeof blocks_text, "%zu blocks%s (the bound: every block the views meet)",
                  blocks_in_memory, blocks_in_memory == blocks ? "" : " in memory at once");
  char text[640];
  std::snprintf(text, sizeof text,
                "TSDF volume %.0f MiB for %s, frames and stage buffers %.0f MiB, mesh and files at the end %.0f MiB, "
                "the process before the run %.0f MiB",
                volume_mb, blocks_text, frames_mb, mesh_mb, process_mb);
  return text;
}

ScanBandBlocks Reconstructor::scanBands() const {
  // The band reaches a truncation either side of a return, as a pixel's band does at least.
  return ScanBandBlocks(config_.volume.voxel_size_m, config_.volume.truncation_m, config_.integrator.min_depth_m,
                        integrator_->allocationDepth());
}

ScanBandBlocks Reconstructor::scanBandsOf(const FrameSource& source, const std::vector<std::size_t>& frames,
                                          const PoseList& T_world_cam0, std::size_t& most_returns) const {
  const PinholeCamera canvas = stages_->lidar.projector().canvasCamera();
  ScanBandBlocks bands = scanBands();
  // The next scan is read while this one's bands are found (one read at a time, off this thread).
  const auto read = [&source, &frames](std::size_t k) {
    return std::async(std::launch::async, [&source, i = frames[k]] { return source.loadScan(i); });
  };
  std::future<pcl::PointCloud<pcl::PointXYZI>::Ptr> next;
  if (!frames.empty())
    next = read(0);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const pcl::PointCloud<pcl::PointXYZI>::Ptr scan = next.get();
    if (k + 1 < frames.size())
      next = read(k + 1);
    bands.addScan(*scan, calibration_.T_cam0_velo, canvas, T_world_cam0[k]);
    most_returns = std::max(most_returns, scan->size());
  }
  return bands;
}

double Reconstructor::blocksPerBandBlock(const FrameSource& source, const std::vector<std::size_t>& frames,
                                         const PoseList& T_world_cam0) {
  const ThreadBudget budget(options_.threads);
  const PinholeCamera canvas = stages_->lidar.projector().canvasCamera();
  double most = 0.0;
  std::size_t last = frames.size();
  for (int c = 0; c < kCalibrationFrames && !frames.empty(); ++c) {
    const std::size_t k = (frames.size() - 1) * static_cast<std::size_t>(c) / (kCalibrationFrames - 1);
    if (k == last)
      continue; // fewer frames than calibration frames: each once
    last = k;
    Frame frame = source.load(frames[k]);
    ScanBandBlocks bands = scanBands();
    bands.addScan(*frame.scan, calibration_.T_cam0_velo, canvas, T_world_cam0[k]);
    // The depth from this engine's own stages, whose buffers the run then reuses; its blocks are
    // those its bands allocate in an empty volume (the carvings update only blocks that exist).
    stages_->history.clear(); // frames far apart: none is another's earlier scan
    FrameResult result = depthOf(frame);
    stages_->history.clear();
    TsdfVolume empty(config_.volume);
    const std::size_t blocks = TsdfIntegrator(empty, config_.integrator)
                                   .bandBlocks(fusedDepthFrame(result, config_.fusion, calibration_.focalBaseline()),
                                               T_world_cam0[k]);
    if (TsdfVolume::bytesFor(blocks) > empty.maxMemoryBytes())
      return 0.0; // a frame whose blocks do not fit the volume's budget: no measure, the bound stays
    if (bands.blocks() > 0)
      most = std::max(most, static_cast<double>(blocks) / static_cast<double>(bands.blocks()));
  }
  return most;
}

namespace {
/// The most of count(centre, radius) over the cameras of a run, taken every `step` metres or more
/// with the radius grown by the step, so that the frames between are covered.
template <typename Count>
std::size_t mostWithin(const PoseList& T_world_cam0, double radius, double step, Count count) {
  Eigen::Vector3d last = T_world_cam0.front().translation();
  std::size_t most = count(last, radius + step);
  for (const Eigen::Isometry3d& T : T_world_cam0)
    if ((T.translation() - last).norm() >= step) {
      last = T.translation();
      most = std::max(most, count(last, radius + step));
    }
  return most;
}
} // namespace

std::size_t Reconstructor::predictedBlocks(std::size_t band_blocks, std::size_t footprint_blocks,
                                           double blocks_per_band_block) const {
  if (!(blocks_per_band_block > 0.0))
    return footprint_blocks;
  const double blocks = std::ceil(kBlockMargin * blocks_per_band_block * static_cast<double>(band_blocks));
  return std::min(footprint_blocks, static_cast<std::size_t>(blocks));
}

std::size_t Reconstructor::blocksInWindow(const MemoryEvidence& evidence) const {
  // A tile stays while its box grown by a block is within the active radius of the camera: its
  // blocks are within the radius plus the box's diagonal; the step keeps 1000 frames to a few
  // hundred balls.
  const double block_m = TsdfBlock::kSide * config_.volume.voxel_size_m;
  const double tile_m = config_.streaming.tile_blocks * block_m;
  const double radius = config_.streaming.active_radius_m + std::sqrt(3.0) * (tile_m + block_m);
  const double step = std::max(tile_m, radius / 8.0);
  return mostWithin(evidence.T_world_cam0, radius, step, [&](const Eigen::Vector3d& centre, double r) {
    return predictedBlocks(evidence.bands.blocksWithin(centre, r), evidence.footprint.blocksWithin(centre, r),
                           evidence.blocks_per_band_block);
  });
}

MemoryEvidence Reconstructor::measureMemory(const FrameSource& source, const std::vector<std::size_t>& frames,
                                            const PoseList& T_world_cam0) {
  const OneCaller call(caller_, "measureMemory");
  const auto start = Clock::now();
  if (frames.size() != T_world_cam0.size())
    throw InvalidInputError("predictMemory: " + std::to_string(frames.size()) + " frames but " +
                            std::to_string(T_world_cam0.size()) + " poses");
  const double process_mb = residentMemoryMb(); // before the calibration frames, whose buffers the run reuses
  // The frames integrated are at most the LiDAR's canvas (the image and its margin), and a
  // frame allocates blocks only in its view, from min_depth_m to allocationDepth().
  const PinholeCamera canvas = stages_->lidar.projector().canvasCamera();
  const double far_m = integrator_->allocationDepth();
  if (!std::isfinite(far_m))
    throw ConfigError("the run's memory cannot be predicted: the band behind a surface has no bound "
                      "(tsdf_integrator.min_pixel_weight 0 with per-pixel weights and truncation_sigmas > 0)");
  BlockFootprint footprint(config_.volume.voxel_size_m);
  for (const Eigen::Isometry3d& T : T_world_cam0)
    footprint.addView(canvas, T, config_.integrator.min_depth_m, far_m);
  std::size_t most_scan_returns = 0;
  MemoryEvidence evidence{T_world_cam0, std::move(footprint),
                          scanBandsOf(source, frames, T_world_cam0, most_scan_returns)};
  evidence.most_scan_returns = most_scan_returns;
  evidence.blocks_per_band_block = blocksPerBandBlock(source, frames, T_world_cam0);
  evidence.process_mb = process_mb;
  evidence.ms = msSince(start);
  return evidence;
}

MemoryPrediction Reconstructor::predictMemory(const MemoryEvidence& evidence, int maps,
                                              double scored_pixels_per_frame) const {
  const auto start = Clock::now();
  MemoryPrediction p;
  p.frames = evidence.T_world_cam0.size();
  p.process_mb = evidence.process_mb;
  p.footprint_blocks = evidence.footprint.blocks();
  p.band_blocks = evidence.bands.blocks();
  p.blocks_per_band_block = evidence.blocks_per_band_block;
  p.blocks = predictedBlocks(p.band_blocks, p.footprint_blocks, p.blocks_per_band_block);
  p.blocks_in_memory = p.blocks;
  if (config_.streaming.enabled() && p.frames > 0)
    p.blocks_in_memory = std::min(p.blocks, blocksInWindow(evidence));
  constexpr double kMiB = 1024.0 * 1024.0;
  const double map_mb = static_cast<double>(TsdfVolume::bytesFor(p.blocks_in_memory)) / kMiB;
  p.volume_mb = map_mb * (1.0 + kOtherMapShare * (maps - 1));
  // The frames in flight: one in each of the three stages (loading, depth, integration) and
  // queue_capacity in each of the two queues between them (no more than the run's frames), over
  // the stages' own buffers; and the pixels of ground truth the caller keeps, each frame's.
  const PinholeCamera canvas = stages_->lidar.projector().canvasCamera();
  const double pixels = static_cast<double>(canvas.width) * canvas.height;
  const double in_flight =
      std::min(static_cast<double>(p.frames), 3.0 + 2.0 * config_.scheduling.queue_capacity);
  const double stage_bytes = pixels * (kStageBytesPerPixel + in_flight * kFrameBytesPerPixel);
  const double kept_bytes = scored_pixels_per_frame * kScoredBytesPerPixel * static_cast<double>(p.frames);
  p.frames_mb = (stage_bytes + kept_bytes) / kMiB;
  // The end of the run: an in-memory map is meshed and written whole, a streamed one tile by
  // tile as the camera moves on, within the window's volume.
  p.mesh_mb = (config_.streaming.enabled() ? kStreamedEndShare : kEndOfRunShare) * map_mb;
  p.total_mb = p.process_mb + p.volume_mb + p.frames_mb + p.mesh_mb;
  p.ms = evidence.ms + msSince(start);
  return p;
}

MemoryPrediction Reconstructor::predictMemory(const FrameSource& source, const std::vector<std::size_t>& frames,
                                              const PoseList& T_world_cam0, int maps,
                                              double scored_pixels_per_frame) {
  return predictMemory(measureMemory(source, frames, T_world_cam0), maps, scored_pixels_per_frame);
}

const TriangleMesh& Reconstructor::mesh() {
  const OneCaller call(caller_, "mesh", true);
  return remesh();
}

const TriangleMesh& Reconstructor::remesh() {
  const ThreadBudget budget(options_.threads);
  mesher_.extract(*volume_, mesh_);
  return mesh_;
}

} // namespace msf
