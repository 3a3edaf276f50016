#pragma once
#include <msf/io/sequence.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace msf {

/// What a run is predicted to hold at its peak, before it starts (Pipeline::predictMemory), in
/// MiB: an upper bound on the TSDF volume from the poses alone (the blocks of every frame's
/// view up to the integrator's allocation depth, BlockFootprint), plus a model of the rest
/// (per pixel of the frames in flight, and a fraction of the volume for the mesh and files
/// written at the end) measured on KITTI and the synthetic street (docs/robustness.md,
/// "Memory budget").
struct MemoryPrediction {
  std::size_t frames = 0;
  std::size_t footprint_blocks = 0;  ///< blocks the frames' views can allocate, in all
  std::size_t blocks_in_memory = 0;  ///< at once: all of them, or with -stream the most within the window
  double process_mb = 0;  ///< the process when predicting (libraries, calibration, config)
  double volume_mb = 0;   ///< the TSDF volume's blocks, map and block list at blocks_in_memory
  double frames_mb = 0;   ///< images, scans, depth and stage buffers of the frames in flight
  double mesh_mb = 0;     ///< the end of an in-memory run: the mesh, its cache, the copies written
  double total_mb = 0;    ///< the sum: the predicted peak
  double ms = 0;          ///< time the prediction took
  /// The terms in words, one line: "TSDF volume 800 MiB for 120000 blocks, frames and stage ...".
  std::string describe() const;
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
  std::string name;                         ///< file stem ("000042")
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
  cv::Mat left;                             ///< camera 0 grey image
  cv::Mat lidar_sparse;       ///< projected scan (step 1), if kept (setKeepSparse)
  cv::Mat lidar_depth;        ///< interpolated LiDAR (step 2)
  cv::Mat lidar_distance;     ///< pixels from each pixel to the nearest real return (step 2)
  /// The same on the LiDAR's canvas, the image grown by projection.margin_px, and its camera:
  /// what the map takes beyond the image's border (fusedDepthFrame).
  cv::Mat lidar_canvas_depth, lidar_canvas_distance;
  PinholeCamera lidar_canvas_camera;
  /// The scan's free space all around (tsdf_integrator.scan_carving_m): what the map clears
  /// outside the camera's view (TsdfIntegrator::carveWithScan).
  ScanFreeSpace scan_free_space;
  cv::Mat stereo_depth;       ///< SGBM (step 3)
  cv::Mat stereo_confidence;  ///< SGBM's confidence in [0, 1]
  /// Fused depth (step 4) with its per-pixel weight and the colour camera's colour: what
  /// the integrator (step 5) consumes.
  DepthFrame fused;
  StageTimes times;
};

/// Free space from the frame's whole scan, after its depth is integrated (see
/// TsdfIntegrator::carveWithScan; nothing when tsdf_integrator.scan_carving_m is 0 or
/// space_carving is off): a return weighs as the fusion weighs a LiDAR-backed pixel, its range noise
/// (fusion.lidar_range_sigma_m). `camera` is the integrated frame's.
void carveWithScan(TsdfIntegrator& integrator, const FrameResult& result, const PinholeCamera& camera,
                   const DepthFusionConfig& fusion, const Calibration& calibration);

/// The whole method (the README's data flow) for a sequence: per frame, LiDAR projection and
/// compound interpolation (LidarCompletion: the scan is projected onto the image grown by
/// a margin, so gaps across the image's border are bridged) run at the same time as SGBM, then the two depth images are
/// fused and integrated into the regularized TSDF volume; marching cubes gives the mesh.
/// The stages are the library's classes with the settings of one PipelineConfig, the same
/// as the msf_project, msf_interpolate, msf_stereo, msf_fuse and msf_integrate tools use,
/// so the chain of tools and the pipeline give the same fused depth. The tools exchange
/// organized clouds; the pipeline runs the same per-pixel code on depth images
/// (LidarCompletion::computeDepth, SgbmStereo::getDepth, DepthImageFusion), which is faster.
///
/// With `pipeline.stereo_prior` (the default) SGBM searches only the disparities that the
/// interpolated LiDAR allows, and with `stereo.guidance: lidar` (the default) the LiDAR's
/// real returns guide it, so steps 1-2 run first; otherwise they run beside SGBM.
/// run() overlaps frames: loading (with steps 1-2 when they feed SGBM), stereo +
/// fusion, and integration each have a thread, joined by bounded queues, so the LiDAR of
/// frame t+2 and the stereo of frame t+1 run while frame t integrates, and memory is
/// bounded by the map, not by the number of frames.
class Pipeline {
public:
  using Ptr = std::shared_ptr<Pipeline>;
  using ConstPtr = std::shared_ptr<const Pipeline>;

  /// Throws ConfigError for an invalid config, CalibrationError when the calibration has no
  /// image size.
  Pipeline(const Calibration& calibration, const PipelineConfig& config);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Depth of one frame, synchronously: steps 1-4. Throws InvalidInputError for images or a
  /// scan that do not fit the calibration.
  FrameResult computeDepth(const Frame& frame);

  /// Integrates the fused depth of `result` at its pose (step 5), grown by the interpolated
  /// LiDAR of the canvas's margin (fusedDepthFrame). Throws InvalidInputError when the frame
  /// has no pose.
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

  /// Runs `frames` of `sequence` through the stages, overlapped. When `stop` becomes true,
  /// the frame being integrated is finished and the frames behind it are dropped, so the
  /// stop is prompt and the volume holds whole frames only. An exception in any stage
  /// stops the run and is rethrown.
  RunStats run(const Sequence& sequence, const std::vector<std::size_t>& frames, const FrameCallback& on_frame,
               const std::atomic<bool>* stop = nullptr);

  /// Also keep each frame's projected scan (step 1) in FrameResult::lidar_sparse, for
  /// pictures; off by default, since step 2 projects the scan itself, with a margin.
  void setKeepSparse(bool keep) { keep_sparse_ = keep; }

  /// Changes each frame before any stage sees it: run() calls it on its loading thread right
  /// after Sequence::load, once per frame in frame order (its time counts as loading). E.g.
  /// the ring hold-out of evaluation protocol 4 removes the held-out rings from the scan
  /// there. It runs beside run()'s callback (the integration thread): what the two share
  /// needs a lock. Set it before run(); computeDepth's caller holds its frame and filters it.
  using FrameFilter = std::function<void(Frame&)>;
  void setFrameFilter(FrameFilter filter) { frame_filter_ = std::move(filter); }

  /// Gives each frame its pose T_world_cam0 on a thread of its own (LiDAR odometry: the
  /// tracking module), beside steps 1-4, which do not need it; integration waits for it.
  /// run() calls it once per frame in frame order, after the frame filter, with the frame's
  /// index, timestamp and scan (no images). It runs beside the filter and the callback: what
  /// they share needs a lock. An exception stops the run like a failing stage. Set it before run().
  using PoseEstimator = std::function<Eigen::Isometry3d(const Frame&)>;
  void setPoseEstimator(PoseEstimator estimator) { pose_estimator_ = std::move(estimator); }

  /// The mesh of the volume, re-meshing only the blocks changed since the last call.
  const TriangleMesh& updateMesh();
  /// What the last updateMesh did (blocks meshed, small pieces removed).
  const MarchingCubes::Stats& meshStats() const { return mesher_.lastStats(); }

  /// With `streaming.active_radius_m` > 0 (docs/streaming.md): the map keeps in memory only
  /// the tiles around the camera and streams the others into `directory` (tiles/*.ply,
  /// tsdf/*.blk); required before run() then. Its time counts as integration. Throws
  /// ConfigError when streaming is off or the radius is below the integrator's reach.
  void setStreamingDirectory(const std::string& directory);
  /// Writes the tiles still in memory and the union of all as `mesh_path`; the volume is
  /// empty afterwards. Returns the triangles written.
  std::size_t finishStreaming(const std::string& mesh_path);
  /// The peak memory of run() over frames seen from `T_world_cam0` (their poses, known before
  /// the run: a dataset's or a file's; not estimated ones), predicted without reading the
  /// frames: see MemoryPrediction. With streaming, the volume term is the most blocks of the
  /// footprint within the active radius (grown by a tile) of any frame's camera. `maps` is the
  /// number of volumes the caller fills from the same frames (msf_reconstruct
  /// -compare_sources: 3); `scores_every_frame`: the caller keeps each frame's ground truth
  /// to the end (protocol 4). Throws ConfigError when the integrator's band has no bound
  /// (reach() is infinite), InvalidInputError for views too large to enumerate.
  MemoryPrediction predictMemory(const PoseList& T_world_cam0, int maps = 1, bool scores_every_frame = false) const;

  /// The streaming map, or nullptr when the map stays in memory.
  const StreamingMap* streaming() const { return streaming_.get(); }

  const PipelineConfig& config() const { return config_; }
  const Calibration& calibration() const { return calibration_; }
  TsdfVolume& volume() { return *volume_; }
  const TsdfVolume& volume() const { return *volume_; }
  const TsdfIntegrator& integrator() const { return *integrator_; }

private:
  struct Stages;  // the stage objects, which keep their buffers from frame to frame

  FrameResult startFrame(const Frame& frame) const;
  /// Steps 1-2 before SGBM: its search range (stereo prior) or its guidance comes from them;
  /// otherwise they run beside it.
  bool lidarBeforeStereo() const;
  void computeLidar(const Frame& frame, FrameResult& result);   // steps 1-2
  void computeStereo(const Frame& frame, FrameResult& result);  // step 3
  void computeFusion(const Frame& frame, FrameResult& result);  // step 4

  Calibration calibration_;
  PipelineConfig config_;
  PinholeCamera camera_;  // of the depth images
  std::unique_ptr<TsdfVolume> volume_;
  std::unique_ptr<TsdfIntegrator> integrator_;
  std::unique_ptr<Stages> stages_;
  MarchingCubes mesher_;
  TriangleMesh mesh_;
  std::unique_ptr<StreamingMap> streaming_;
  bool keep_sparse_ = false;
  FrameFilter frame_filter_;
  PoseEstimator pose_estimator_;
};

} // namespace msf
