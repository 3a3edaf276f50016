// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/crumb_metric.h>
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/ghost_metric.h>
#include <msf/evaluation/lidar_support.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/evaluation/off_surface_split.h>
#include <msf/evaluation/open_sky_coverage.h>
#include <msf/io/calibration.h>
#include <msf/io/frame_source.h>
#include <msf/io/surface_classes.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/run_report.h>
#include <msf/synthetic/ground_truth.h>

#include <pcl/PolygonMesh.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace msf {

/// A synthetic sequence's exact ground truth (its gt/ folder) scored over a run (protocol 3):
/// each frame's depth images against the true depth (all, background, foreground), and after
/// the run the meshes against the true surface (accuracy, completeness, by class of surface),
/// where moving objects were before the last frame (ghosts), over the true sky, and off the
/// surface (OffSurfaceSplit).
class SyntheticScoring {
public:
  /// Reads gt/scene.ply and gt/scene_classes.txt now, so that a garbled file stops the run
  /// before its first frame. `score_meshes` false (a streamed map, whose mesh is on disk)
  /// keeps the depth scores only and nothing per frame beyond them. `voxel_size_m`: the cell
  /// of the LiDAR's support. Throws IOError naming a garbled file.
  SyntheticScoring(const std::string& ground_truth_dir, bool score_meshes, double voxel_size_m);

  const synthetic::GroundTruth& truth() const { return *truth_; }
  /// The true depth of a frame, by its name ("000042").
  cv::Mat depth(const std::string& frame_name) const;

  /// The scan the engine integrates for `frame` (after any hold-out), kept until addFrame places
  /// it in the world at the frame's pose: the LiDAR's support of the meshes. Any thread.
  void addScan(const Frame& frame);
  /// Scores the frame's SGBM, interpolated LiDAR and fused depth against `true_depth`, keeps
  /// every 4th pixel of the true static surface within `max_depth_m` for completeness, the
  /// true sky (zero true depth) at the frame's pose and its scan (addScan) in the world.
  /// `moving`: the frame's GroundTruth::movingMask, when the caller has read it (read here
  /// otherwise, if the meshes are scored).
  void addFrame(const FrameResult& result, const cv::Mat& true_depth, const Calibration& calibration,
                double max_depth_m, const cv::Mat& moving = cv::Mat());
  /// Scores another method's depth of the frame (the paper's).
  void addDepth(const std::string& method, const std::string& frame_name, const cv::Mat& true_depth,
                const cv::Mat& estimate, double focal_baseline);

  /// A mesh to score: the marching cubes mesh (its vertex weights give the weight curve) and
  /// the same as a PolygonMesh.
  struct MeshToScore {
    const TriangleMesh* mesh = nullptr;
    const pcl::PolygonMesh* polygons = nullptr;
  };
  struct MeshScores {
    MeshAccuracy accuracy;
    bool has_ghosts = false;  ///< ghosts and crumbs: the dataset has moving-object boxes
    GhostMetrics ghosts;
    CrumbMetrics crumbs;
    SkyCoverage true_sky;          ///< the true sky the mesh rendered at every frame's pose covers (addTrueSkyViews)
    SkyCoverage true_sky_sheets;   ///< of it, the pixels whose covering surface is off the true surface
    OffSurfaceSplit off_surface;   ///< by height above the road and the LiDAR's support
  };
  /// The heights that split the surface off the truth (m above the road): below 2 m the road's
  /// cars, people and their ghosts; 2-5 m trunks, signs and the lower crowns; above 5 m the
  /// crowns' tops, lamps, upper floors and what SGBM hangs in the sky beside them.
  static const std::vector<double>& offSurfaceBands();
  /// Each mesh against the true surface; `voxel_size_m` sets the completeness threshold (2
  /// voxels) and the margin around moving boxes (a voxel). Ghosts and crumbs lie where a moving
  /// object was at a frame scored and is not at the last one (where it stands then is real).
  /// The true sky is counted apart, from the mesh's views (addTrueSkyViews).
  std::map<std::string, MeshScores> scoreMeshes(const std::map<std::string, MeshToScore>& meshes,
                                                double voxel_size_m) const;
  /// The true sky a mesh covers, counted view by view: all of it, and where the covering surface
  /// is off the true surface (a sheet, not a blurred outline).
  struct TrueSky {
    OpenSkyCoverage::Tally all, sheets;
  };
  /// Counts into `tally` the true sky of every frame scored that the mesh `views` renders covers
  /// (the views are shared with the other scorers of the frames); nothing without mesh scores.
  void addTrueSkyViews(MeshViewScoring& views, TrueSky& tally) const;
  /// The depth scores by method into the report.
  void writeDepthScores(RunReport& report) const;
  /// Why a ghost figure is absent, in words ("" when moving boxes exist).
  std::string noGhostsReason() const;

private:
  /// Scores `estimate` against the frame's true depth, over all its pixels and split.
  void addDepth(const std::string& method, const synthetic::GroundTruth::Split& split, const cv::Mat& true_depth,
                const cv::Mat& estimate, double focal_baseline);

  std::unique_ptr<synthetic::GroundTruth> truth_;
  std::map<std::string, DepthErrorAccumulator> all_, background_, foreground_;
  std::vector<Eigen::Vector3f> seen_surface_;  // ground-truth depth back-projected to the world
  std::vector<float> seen_depth_;              // the depth each was seen at
  pcl::PolygonMesh scene_;                     // gt/scene.ply
  std::unique_ptr<SurfaceDistance> static_surface_; // the distance to it
  std::optional<SurfaceClasses> classes_;      // gt/scene_classes.txt, when the dataset has it
  bool score_meshes_ = true;
  std::optional<std::size_t> last_frame_;      // the latest ground-truth frame scored: where cars stand at the end
  std::unique_ptr<OpenSkyCoverage> true_sky_;  // made at the first frame, with its camera
  LidarSupport lidar_;
  std::mutex scans_mutex_;                     // addScan's thread and addFrame's
  std::map<std::size_t, pcl::PointCloud<pcl::PointXYZI>::ConstPtr> scans_;
};

} // namespace msf
