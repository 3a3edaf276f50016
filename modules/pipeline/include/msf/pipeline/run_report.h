// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/crumb_metric.h>
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/ghost_metric.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/evaluation/odometry_metrics.h>
#include <msf/evaluation/off_surface_split.h>
#include <msf/evaluation/open_sky_coverage.h>
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/pipeline/reconstructor.h>

#include <iosfwd>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace msf {

/// What msf_reconstruct tells at the end of a run: per-frame stage times, the map's size,
/// and, where ground truth exists, the depth and mesh errors. Writes summary.json,
/// frames.csv, runtime.png (the paper's Figs. 7-8: milliseconds per stage per frame) and
/// report.md, each atomically.
class RunReport {
public:
  struct FrameRow {
    std::size_t index = 0;
    std::string name;
    StageTimes times;
    double latency_ms = 0;  ///< from the start of its loading to the end of its integration
    double rss_mb = 0;      ///< resident memory of the process after it (0: not measured)
    /// FrameResult's (NaN: no pixel with both)
    double lidar_stereo_disagreement = std::numeric_limits<double>::quiet_NaN();
  };

  /// Depth errors of one method over all frames: every pixel with ground truth, and the
  /// KITTI devkit's split into background and foreground when an object map exists.
  struct DepthScores {
    DepthMetrics all, background, foreground;
    bool has_split = false;
  };

  /// Evaluation protocol 4: the map against ground truth it never saw (msf_reconstruct
  /// -holdout, or a synthetic sequence), one row per depth source.
  struct MapEvaluation {
    struct Row {
      ReconstructionScore score;   ///< source "mesh", "fused", "mesh_lidar" or "mesh_stereo"
      bool has_accuracy = false;   ///< a mesh against the true surface (synthetic)
      MeshAccuracy accuracy;
      bool has_ghosts = false;     ///< a mesh where moving objects were: ghosts and crumbs
      GhostMetrics ghosts;
      CrumbMetrics crumbs;
      bool has_seen_through = false; ///< a mesh: its small pieces the ground truth sees through
      SeenThroughPieces seen_through;
      /// A mesh against the true surface (synthetic): the true sky it covers, rendered at every
      /// frame's pose (all of it, and by surface off the truth: sheets), and its area off the
      /// surface by height and LiDAR support.
      SkyCoverage true_sky, true_sky_sheets;
      OffSurfaceSplit off_surface;
    };
    std::string truth;             ///< what the ground truth is, in words
    double range_m = 0;            ///< "within range": true depth <= this (tsdf_integrator.max_depth_m)
    std::size_t frames = 0, gt_pixels = 0;
    bool moving_split = false;     ///< the dataset marks moving objects (gt/moving_0)
    /// the scans split the static pixels within range into lasting and transient ones
    bool transient_split = false;
    std::string no_ghosts;         ///< why there is no ghost figure, when there is none
    std::vector<Row> rows;         ///< empty without ground truth
    /// The fused mesh's row ("mesh") when it has a weight curve (MeshAccuracy::by_weight), else null.
    const Row* fusedCurveRow() const;
  };

  std::string dataset;            ///< folder reconstructed
  std::string layout;             ///< odometry, raw or synthetic
  std::string trajectory;         ///< where the poses came from, in words (PoseSource::description)
  std::vector<double> pose_ms;    ///< per frame, when the poses were estimated (the odometry's thread)
  /// The poses used against the dataset's own (protocol 5), when they came from elsewhere.
  bool has_trajectory_metrics = false;
  OdometryMetrics trajectory_metrics;
  std::string trajectory_reference;  ///< what they were compared with, in words
  std::size_t frames_requested = 0;
  bool interrupted = false;
  /// Optional outputs a second stop signal left out (msf_reconstruct: "compare_sources",
  /// "mesh_preview", "mesh_accuracy", "reconstruction_evaluation", "open_sky"), in the order skipped.
  std::vector<std::string> skipped;
  double wall_s = 0;
  double first_frame_s = 0;       ///< when the first frame was done, from the start
  double mesh_ms = 0;
  double peak_memory_mb = 0;
  /// The peak predicted before the run (Reconstructor::predictMemory); < 0 when the poses were not
  /// known before it (estimated), written as null.
  double predicted_memory_mb = -1;
  std::size_t observed_voxels = 0, blocks = 0, vertices = 0, triangles = 0;
  std::size_t pieces_removed = 0, triangles_removed = 0; ///< marching_cubes.min_component_triangles
  double volume_memory_mb = 0;
  double voxel_size_m = 0;
  double lambda = 0;
  std::vector<FrameRow> frames;
  std::map<std::string, DepthScores> depth;  ///< by method: sgbm, interpolated, fused
  bool has_mesh_accuracy = false;
  MeshAccuracy mesh_accuracy;
  MapEvaluation map_evaluation;
  /// Evaluation protocol 6: the open sky each mesh covers, by mesh ("mesh", "mesh_lidar", ...),
  /// and the pictures of it (sky_NNNNNN.png); empty when not measured.
  std::map<std::string, SkyCoverage> open_sky;
  std::vector<std::string> sky_pictures;
  /// The effective configuration (PipelineConfig::print: every key of every section, after
  /// defaults, the file and the flags), written into summary.json; "" leaves it out.
  std::string config_yaml;
  std::string config_file;                    ///< its copy beside the report, e.g. config.yaml
  std::vector<std::string> depth_panels;      ///< file names of the depth panels written
  std::string mesh_file = "mesh.ply", volume_file = "volume.pcd", preview_file;
  std::string poses_file = "poses.txt";        ///< the poses used, T_world_cam0 in KITTI's format
  std::string trajectory_plot_file;            ///< them from above (with the reference), if drawn

  /// Frames over the whole run, wall_s: with the first frame's way through the empty pipeline.
  double framesPerSecond() const;
  /// The rate once the pipeline is full: frames 2..N over the time after the first was done
  /// (0 with fewer than 2 frames). What keeping up with a sensor needs.
  double framesPerSecondAfterFirst() const;
  /// The frames' disagreement between LiDAR and stereo, each frame's (NaN where none measured).
  std::vector<double> lidarStereoDisagreements() const;

  void writeFramesCsv(const std::string& path) const;
  void writeSummaryJson(const std::string& path) const;
  void writeRuntimePlot(const std::string& path) const;
  void writeMarkdown(const std::string& path) const;

private:
  // summary.json's sections, in the order written.
  void writeTrajectoryJson(std::ostream& out) const;
  /// Frames, stop signals, rates, memory and the stages' times.
  void writeSpeedJson(std::ostream& out) const;
  /// The map's size, the depth errors and the mesh's accuracy.
  void writeMapJson(std::ostream& out) const;

  // report.md's sections, in the order written.
  /// The title, the dataset, the trajectory and how it compares with the reference.
  void writeIntro(std::ostream& out) const;
  void writeSpeed(std::ostream& out) const;
  /// The map's size, its files and the mesh preview.
  void writeMapSize(std::ostream& out) const;
  void writeMapEvaluation(std::ostream& out) const;
  void writeOpenSky(std::ostream& out) const;
  /// The true sky each mesh covers and its surface off the truth (synthetic rows).
  void writeTruthOffSurface(std::ostream& out) const;
  /// The meshes' accuracy and completeness by the class of the true surface (when known).
  void writeClassTable(std::ostream& out) const;
  /// The depth panels, then links to the other outputs.
  void writeDepthImagesAndLinks(std::ostream& out) const;
};

/// Peak resident memory of this process so far, in MiB (getrusage).
double peakMemoryMb();
/// Resident memory of this process now, in MiB (/proc/self/statm; 0 where there is none).
double residentMemoryMb();

} // namespace msf
