// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/range_image/scan_history.h>
#include <msf/reconstruction/block_footprint.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/scan_band_blocks.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>
#include <msf/registration/lidar_odometry.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

namespace msf {

/// What a run is predicted to hold at its peak, before it starts (Reconstructor::predictMemory), in
/// MiB. The TSDF volume's blocks are the blocks within the truncation band of the scans' returns
/// in view (ScanBandBlocks, from the scans and the poses), times the blocks the fused depth
/// allocates per such block, counted on a few of the run's frames (TsdfIntegrator::bandBlocks),
/// and never more than the blocks of every frame's view (BlockFootprint, the bound from the
/// poses alone); the rest is a model (per pixel of the frames in flight, and a share of the
/// volume for the mesh and files written at the end) measured on KITTI and the synthetic
/// street (docs/robustness.md, "Memory budget").
struct MemoryPrediction {
  std::size_t frames = 0;
  std::size_t footprint_blocks = 0;  ///< blocks the frames' views can allocate, in all: the bound
  std::size_t band_blocks = 0;       ///< blocks within the band of the scans' returns in view, in all
  double blocks_per_band_block = 0;  ///< measured on the calibration frames; 0 when not measured
  std::size_t blocks = 0;            ///< blocks the run is predicted to allocate, in all
  std::size_t blocks_in_memory = 0;  ///< at once: all of them, or with -stream the most within the window
  double process_mb = 0;  ///< the process when predicting (libraries, calibration, config)
  double volume_mb = 0;   ///< the TSDF volumes' blocks, maps and block lists at blocks_in_memory
  double frames_mb = 0;   ///< images, scans, depth and stage buffers of the frames in flight
  double mesh_mb = 0;     ///< the end of the run: the mesh, its cache, the copies written
  double total_mb = 0;    ///< the sum: the predicted peak
  double ms = 0;          ///< time the prediction took
  /// The terms in words, one line: "TSDF volume 800 MiB for 120000 blocks, frames and stage ...".
  std::string describe() const;
};

/// What the memory prediction measures from a run's data before it starts
/// (Reconstructor::measureMemory): the blocks of the views, the blocks within the scans' bands,
/// the share the fused depth adds on the calibration frames, and the process. Measured once, it
/// serves the predictions of the run in memory and streamed alike.
struct MemoryEvidence {
  PoseList T_world_cam0;             ///< the run's poses, one per frame
  BlockFootprint footprint;          ///< the blocks every frame's view meets: the bound
  ScanBandBlocks bands;              ///< the blocks within the band of the scans' returns in view
  double blocks_per_band_block = 0;  ///< measured on the calibration frames; 0 when not measured
  std::size_t most_scan_returns = 0; ///< the most returns a scan of the run holds
  double process_mb = 0;             ///< the process before the calibration frames
  double ms = 0;                     ///< time the measure took
};

/// Milliseconds each stage spent on one frame. lidar = projection + interpolation;
/// depth_ms = steps 1-3 (lidar + stereo, or their wall time when they run side by side).
struct StageTimes {
  double load_ms = 0, lidar_ms = 0, stereo_ms = 0, depth_ms = 0, fusion_ms = 0, integrate_ms = 0;
};

/// What one frame produced on its way through the stages: depth images of camera 0
/// (CV_32FC1 metres, 0 = none), which is all the stages exchange, so a frame moves a quarter
/// of the memory of organized clouds and no stage converts.
struct FrameResult {
  std::size_t index = 0;                    ///< position in the sequence
  std::string name;                         ///< the source's frame name ("000042") under run(); addFrame's: empty
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
  /// What an engine knows the result by, unique in the process (0: not yet known to one): a map
  /// takes a result once, since a second time would double its weight.
  std::uint64_t serial = 0;
  cv::Mat left;                             ///< camera 0 grey image
  cv::Mat lidar_sparse;       ///< projected scan (step 1), if kept (setKeepSparse)
  cv::Mat lidar_depth;        ///< interpolated LiDAR (step 2)
  cv::Mat lidar_distance;     ///< pixels from each pixel to the nearest real return (step 2)
  /// The same on the LiDAR's canvas, the image grown by projection.margin_px, and its camera:
  /// what the map takes beyond the image's border (fusedDepthFrame).
  cv::Mat lidar_canvas_depth, lidar_canvas_distance;
  PinholeCamera lidar_canvas_camera;
  /// The scan's free space all around (tsdf_integrator.scan_carving_m): what the map clears
  /// where the camera's depth does not (TsdfIntegrator::carveWithScan).
  ScanFreeSpace scan_free_space;
  /// The frame's open sky (SkyMask, CV_8UC1 of camera 0's size, 255 = sky; the fusion's when it
  /// found one, fusion.clear_sky): where no hole is filled.
  cv::Mat sky;
  /// How far the map clears along each of its rays (tsdf_integrator.sky_carving,
  /// TsdfIntegrator::carveSky; CV_32FC1, DepthImageFusion::findOpenSky): NaN off the sky, the
  /// depth of the LiDAR's highest return near the pixel's column, +inf in the clear sky, which only
  /// the sky looks like, and where the column has no return. The fused cloud's sky_depth.
  cv::Mat sky_depth;
  cv::Mat stereo_depth;       ///< SGBM (step 3)
  cv::Mat stereo_confidence;  ///< SGBM's confidence in [0, 1]
  /// Fused depth (step 4) with its per-pixel weight and the colour camera's colour: what
  /// the integrator (step 5) consumes. Once integrated, with map_prior.enabled, its holes hold the
  /// map's depth where earlier frames saw a surface, and the small holes left the nearest depth at
  /// weight 0 (fusion.hole_fill_px); neither was integrated.
  DepthFrame fused;
  /// Of the pixels with a real LiDAR return and a stereo depth, the share where the two differ
  /// by more than 10 % (lidarStereoDisagreement): a few percent with a right rig; NaN: none.
  double lidar_stereo_disagreement = std::numeric_limits<double>::quiet_NaN();
  StageTimes times;
};

/// What the frame showed free beside its depth, for TsdfIntegrator::integrateFrame: its scan's
/// rays (with `with_scan`), its open sky (FrameResult::sky_depth, of `sky_camera`, camera 0) and its rays
/// beyond the range, each weighing as a LiDAR return does (fusion.lidar_range_sigma_m), since they
/// are as surely free.
TsdfIntegrator::FreeSpace freeSpaceOf(const FrameResult& result, const PinholeCamera& sky_camera,
                                      const DepthFusionConfig& fusion, const Calibration& calibration,
                                      bool with_scan = true);

/// The pixels the map prior fills (section map_prior): the fused depth's holes (no depth, 0 or
/// NaN) that are not open sky. CV_8UC1 of the fused depth's size, 255 = a hole.
cv::Mat mapPriorHoles(const FrameResult& result);

/// The reconstruction engine: the whole method (the data flow of docs/design.md) as one object that
/// any door drives (msf_reconstruct, the Python module, the ROS node, the batch job). Per
/// frame, LiDAR projection and compound interpolation (LidarCompletion: the scan is projected
/// onto the image grown by a margin, so gaps across the image's border are bridged; the last few
/// scans, placed by the poses, add their returns between the current rings: ScanHistory) and SGBM
/// stereo give two depth images, fused per pixel; the frame's pose (its own, or LiDAR
/// odometry's) places the fused depth in the regularized TSDF volume; marching cubes gives the
/// mesh, incrementally. The stages are the library's classes with the settings of one
/// PipelineConfig, the same as the msf_project, msf_interpolate, msf_stereo, msf_fuse and
/// msf_integrate tools use, so the chain of tools and the engine give the same fused depth.
///
/// Two ways to feed it:
///  - addFrame(frame), one call per frame on the caller's thread (a ROS callback, a notebook);
///  - run(source, frames, ...), which overlaps frames: loading (with steps 1-2 when they feed
///    SGBM), stereo + fusion, integration, and the odometry each have a thread, joined by
///    bounded queues, so memory is bounded by the map, not by the number of frames.
/// Both give the same map for the same frames. One call at a time, as PCL's classes: a call
/// made while another thread is in one of this engine's calls throws Error rather than corrupt
/// the map (guard it with a mutex, or give each thread its own engine); run()'s callback may
/// call mesh() only.
///
/// With `pipeline.stereo_prior` (the default) SGBM searches only the disparities that the
/// interpolated LiDAR allows, and with `stereo.guidance: lidar` (the default) the LiDAR's real
/// returns guide it, so steps 1-2 run first; otherwise they run beside SGBM.
class Reconstructor {
public:
  using Ptr = std::shared_ptr<Reconstructor>;

  /// Where each frame's pose comes from.
  enum class PoseMode {
    Auto,     ///< the frame's own pose; LiDAR odometry for a run whose first frame has none
    Given,    ///< the frame's own pose; a frame without one is an error
    Odometry, ///< LiDAR odometry, in the world of the first frame's pose when it has one
    /// The frame's own pose (a GPS/INS's) as a prior that the LiDAR odometry refines: its motion
    /// since the previous frame is the scan's prediction and a soft constraint weighed by its
    /// accuracy (odometry.prior_*_sigma_*), so the scans correct a drifting heading and a scene
    /// they cannot pin down (a tunnel, an open field) keeps the prior's motion; in the world of
    /// the first frame's pose. A frame without a pose is an error.
    Refine,
  };

  struct Options {
    PoseMode poses = PoseMode::Auto;
    /// Threads of this object's parallel loops: 0 = all cores, 1 = only the thread that calls
    /// (run() still overlaps its stages), n = at most n at a time. For a process that shares
    /// the machine (a ROS node, a Python program).
    int threads = 0;
    /// With `streaming.active_radius_m` > 0 (docs/streaming.md): the folder where the map
    /// streams the tiles that leave the active radius (tiles/*.ply, tsdf/*.blk); integration
    /// needs it then.
    std::string stream_directory;
    /// Also keep each frame's projected scan (step 1) in FrameResult::lidar_sparse, for
    /// pictures; off by default, since step 2 projects the scan itself, with a margin.
    bool keep_sparse = false;
  };

  /// The rig's LiDAR decides how its scans are taken (rig.lidar.sweeping): swept over their
  /// period, the odometry deskews them (odometry.deskew auto) and the scan's carving allows for
  /// their skew (ScanFreeSpace::skew). Throws ConfigError for an invalid config or streaming
  /// options, CalibrationError for a rig that is not physical (Calibration::validate) or has no
  /// image size.
  Reconstructor(const Calibration& rig, const PipelineConfig& config, const Options& options);
  Reconstructor(const Calibration& rig, const PipelineConfig& config);
  ~Reconstructor();
  Reconstructor(const Reconstructor&) = delete;
  Reconstructor& operator=(const Reconstructor&) = delete;

  /// One frame, synchronously: its depth (steps 1-4), its pose (the frame's or the odometry's,
  /// as Options::poses says) and its integration into the map (step 5). Returns the frame's
  /// depth images, weight and the pose used. Throws InvalidInputError for images or a scan
  /// that do not fit the rig (checkFrame), or a frame without a pose where one is needed,
  /// before anything changes: the engine is as it was, and the frame can be given again. A frame
  /// given twice in a row (the same scan object as the frame it took last) is refused too: the
  /// map would take it twice.
  FrameResult addFrame(const Frame& frame);

  /// Depth of one frame, synchronously: steps 1-4, nothing added to the map. With
  /// `accumulation.scans` > 0 and a frame with a pose, step 1 adds the earlier frames' scans
  /// (ScanHistory) and the frame's scan joins them: call it with the frames in order.
  FrameResult computeDepth(const Frame& frame);
  /// Integrates the fused depth of `result` at its pose (step 5), grown by the interpolated
  /// LiDAR of the canvas's margin (fusedDepthFrame). Throws InvalidInputError when the frame
  /// has no pose, was computed for another rig (its camera differs from this engine's), or when
  /// this map took the result already (addFrame's and run()'s results included): a second time
  /// would double its weight.
  void integrate(FrameResult& result);

  struct RunStats {
    std::size_t frames_done = 0;
    double wall_s = 0;
    /// When the first frame was done (integrated and passed to the callback), from the start:
    /// the pipeline has filled then, and later frames leave it at its steady rate.
    double first_frame_s = 0;
    bool interrupted = false;  ///< stopped by the stop flag before the last frame
  };
  /// Called on the integration thread after each frame is integrated, in frame order.
  using FrameCallback = std::function<void(FrameResult&)>;

  /// Runs `frames` of `source` through the stages, overlapped. When `stop` becomes true, the
  /// frame being integrated is finished and the frames behind it are dropped, so the stop is
  /// prompt and the volume holds whole frames only. An exception in any stage stops the run
  /// and is rethrown.
  RunStats run(const FrameSource& source, const std::vector<std::size_t>& frames, const FrameCallback& on_frame,
               const std::atomic<bool>* stop = nullptr);

  /// Changes each frame before any stage sees it: run() calls it on its loading thread right
  /// after FrameSource::load, once per frame in frame order (its time counts as loading). E.g.
  /// the ring hold-out of evaluation protocol 4 removes the held-out rings from the scan
  /// there. It runs beside run()'s callback (the integration thread): what the two share
  /// needs a lock. Set it before run(); addFrame's caller holds its frame and changes it.
  using FrameFilter = std::function<void(Frame&)>;
  void setFrameFilter(FrameFilter filter) { frame_filter_ = std::move(filter); }

  /// The mesh of the map, re-meshing only the blocks changed since the last call.
  const TriangleMesh& mesh();
  /// What the last mesh() did (blocks meshed, small pieces removed).
  const MarchingCubes::Stats& meshStats() const { return mesher_.lastStats(); }

  /// A streamed map (Options::stream_directory): writes the tiles still in memory and the
  /// union of all as `mesh_path`; the volume is empty afterwards. Returns the triangles written.
  std::size_t finishStreaming(const std::string& mesh_path);
  /// What the peak memory of run() over `frames` of `source` seen from `T_world_cam0` (one per
  /// frame, known before the run: a dataset's or a file's; not estimated ones) is predicted from:
  /// it reads every frame's scan, and computes the depth of a few frames (with this object's
  /// stages) and counts the blocks it would allocate (TsdfIntegrator::bandBlocks). Throws
  /// ConfigError when the integrator's band has no bound (reach() is infinite),
  /// InvalidInputError for views too large to enumerate or frames and poses of different counts.
  MemoryEvidence measureMemory(const FrameSource& source, const std::vector<std::size_t>& frames,
                               const PoseList& T_world_cam0);
  /// The peak memory of run() predicted from `evidence` (measured by an engine of the same volume,
  /// integrator and projection configuration, streamed or not): see MemoryPrediction. With
  /// streaming, the volume term is the most blocks within the active radius (grown by a tile) of
  /// any frame's camera. `maps` is the number of volumes the caller fills from the same frames
  /// (msf_reconstruct -compare_sources: 3); `scored_pixels_per_frame`: the pixels of each frame
  /// whose ground truth the caller keeps to the end (protocol 4): a synthetic drive's every pixel,
  /// the held-out rings' returns under -holdout; 0: none.
  MemoryPrediction predictMemory(const MemoryEvidence& evidence, int maps = 1,
                                 double scored_pixels_per_frame = 0) const;
  /// Both: measureMemory, then predictMemory from it.
  MemoryPrediction predictMemory(const FrameSource& source, const std::vector<std::size_t>& frames,
                                 const PoseList& T_world_cam0, int maps = 1, double scored_pixels_per_frame = 0);

  /// The least streaming.active_radius_m a streamed map of this run accepts: the integrator's
  /// reach over the LiDAR's canvas plus a tile (StreamingMap::minimumRadius).
  double minimumStreamingRadius() const;

  /// The streaming map, or nullptr when the map stays in memory.
  const StreamingMap* streaming() const { return streaming_.get(); }
  /// Milliseconds the odometry took for each frame it tracked (empty when it did not run).
  const std::vector<double>& odometryMs() const { return odometry_ms_; }
  /// What the engine did that its caller may not expect, a line each in the order they arose, for
  /// the door to say: in PoseMode Auto, the own poses of later frames, which the odometry replaced
  /// because the first frame had none; a frame whose time (Frame::timestamp) is before the one
  /// taken just before it.
  std::vector<std::string> notes() const;

  /// The configuration the stages run with: the one given, adapted to the rig (adaptToRig).
  const PipelineConfig& config() const { return config_; }
  const Calibration& calibration() const { return calibration_; }
  const Options& options() const { return options_; }
  TsdfVolume& volume() { return *volume_; }
  const TsdfVolume& volume() const { return *volume_; }
  const TsdfIntegrator& integrator() const { return *integrator_; }
  /// The earlier scans step 1 carries into the next frame's view (accumulation.scans).
  const ScanHistory& scanHistory() const;

private:
  struct Stages;  // the stage objects, which keep their buffers from frame to frame
  struct Run;     // one run(): its queues and stage loops

  FrameResult startFrame(const Frame& frame) const;
  /// Steps 1-2 before SGBM: its search range (stereo prior) or its guidance comes from them;
  /// otherwise they run beside it.
  bool lidarBeforeStereo() const;
  /// Steps 1-4 into a started result, at its pose (the earlier scans are placed by it).
  void computeDepth(const Frame& frame, FrameResult& result);
  /// computeDepth(), integrate() and mesh() within a call that holds the engine (addFrame, run,
  /// measureMemory).
  FrameResult depthOf(const Frame& frame);
  void integrateResult(FrameResult& result);
  const TriangleMesh& remesh();
  /// The fused depth's holes filled before the frame is integrated, in new images (the
  /// integration frame shares the old): first from the map (section map_prior, fillFromMap),
  /// then the small holes left (fusion.hole_fill_px, msf::fillSmallHoles).
  void fillHoles(FrameResult& result) const;
  /// The fused depth's holes (no depth; not open sky) filled with the map's surface seen from
  /// the frame's pose (MapRaycaster): what earlier frames saw where this one sees nothing. In
  /// the images fillHoles made new.
  void fillFromMap(FrameResult& result) const;
  void computeLidar(const Frame& frame, FrameResult& result);   // steps 1-2
  void computeStereo(const Frame& frame, FrameResult& result);  // step 3
  void computeFusion(const Frame& frame, FrameResult& result);  // step 4
  /// The frame's open sky (FrameResult::sky), whether or not the map carves along it.
  void computeSky(FrameResult& result);
  /// Whether frames from `first` on are tracked by the odometry (PoseMode).
  bool tracks(const Frame& first) const;
  /// The odometry's pose of the frame's scan; frames in order.
  Eigen::Isometry3d track(const Frame& frame, const std::string& scan_name);
  /// Says (notes()) the first frame whose time is before the one taken just before it: taken
  /// still, since a drive given backwards with its poses makes a good map, but the odometry
  /// predicts each scan's motion from the scans before it and the earlier scans (accumulation)
  /// are the frames taken last.
  void checkTimeOrder(const Frame& frame);
  void say(std::string note);
  /// PoseMode::Refine: the LiDAR's motion since the previous frame by the frames' own poses
  /// (the identity for the first); nullopt in the other modes.
  std::optional<Eigen::Isometry3d> measuredMotion(const Frame& frame);
  void startStreaming();
  // The memory prediction's steps (predictMemory).
  ScanBandBlocks scanBands() const;
  /// The scans' bands, and in `most_returns` the most returns a scan holds.
  ScanBandBlocks scanBandsOf(const FrameSource& source, const std::vector<std::size_t>& frames,
                             const PoseList& T_world_cam0, std::size_t& most_returns) const;
  /// The blocks a frame's fused depth allocates per block of its scan's band, the most over a few
  /// frames spread over the run; 0 when none could be measured.
  double blocksPerBandBlock(const FrameSource& source, const std::vector<std::size_t>& frames,
                            const PoseList& T_world_cam0);
  std::size_t predictedBlocks(std::size_t band_blocks, std::size_t footprint_blocks,
                              double blocks_per_band_block) const;
  std::size_t blocksInWindow(const MemoryEvidence& evidence) const;

  Calibration calibration_;
  PipelineConfig config_;
  Options options_;
  PinholeCamera camera_;  // of the depth images
  std::unique_ptr<TsdfVolume> volume_;
  std::unique_ptr<TsdfIntegrator> integrator_;
  std::unique_ptr<Stages> stages_;
  MarchingCubes mesher_;
  TriangleMesh mesh_;
  std::unique_ptr<StreamingMap> streaming_;
  FrameFilter frame_filter_;
  // The odometry (PoseMode): made at the first frame it tracks, anchored at that frame's pose.
  std::unique_ptr<LidarOdometry> odometry_;
  Eigen::Isometry3d T_world_cam0_first_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_velo_measured_last_ = Eigen::Isometry3d::Identity();  // PoseMode::Refine's prior
  std::vector<double> odometry_ms_;
  bool poses_not_used_ = false;        // PoseMode Auto: a frame tracked though it had a pose
  std::optional<double> last_time_s_;  // the time of the frame taken last (run(): loaded last)
  bool time_went_back_ = false;        // said once
  mutable std::mutex notes_mutex_;     // run() says notes from its loading and its odometry threads
  std::vector<std::string> notes_;
  /// The thread in a public call that changes the engine (OneCaller; the class comment).
  std::atomic<std::thread::id> caller_{};
  std::unordered_set<std::uint64_t> integrated_;  // the results' serials this map took
  std::size_t frames_added_ = 0;  // by addFrame: its first frame decides PoseMode::Auto
  bool add_tracks_ = false;
  std::weak_ptr<const pcl::PointCloud<pcl::PointXYZI>> last_scan_;  // of the last frame addFrame took
};

} // namespace msf
