// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/ghost_metric.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/io/calibration.h>
#include <msf/io/surface_classes.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/run_report.h>
#include <msf/synthetic/ground_truth.h>

#include <pcl/PolygonMesh.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace msf {

/// A synthetic sequence's exact ground truth (its gt/ folder) scored over a run (protocol 3):
/// each frame's depth images against the true depth (all, background, foreground), and after
/// the run the meshes against the true surface (accuracy, completeness, by class of surface)
/// and where moving objects were (ghosts).
class SyntheticScoring {
public:
  /// Reads gt/scene.ply and gt/scene_classes.txt now, so that a garbled file stops the run
  /// before its first frame. `score_meshes` false (a streamed map, whose mesh is on disk)
  /// keeps the depth scores only and nothing per frame beyond them. Throws IOError naming a
  /// garbled file.
  SyntheticScoring(const std::string& ground_truth_dir, bool score_meshes);

  const synthetic::GroundTruth& truth() const { return *truth_; }
  /// The true depth of a frame, by its name ("000042").
  cv::Mat depth(const std::string& frame_name) const;

  /// Scores the frame's SGBM, interpolated LiDAR and fused depth against `true_depth` and
  /// keeps every 4th pixel of the true static surface within `max_depth_m` for completeness.
  void addFrame(const FrameResult& result, const cv::Mat& true_depth, const Calibration& calibration,
                double max_depth_m);
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
    bool has_ghosts = false;
    GhostMetrics ghosts;
  };
  /// Each mesh against the true surface; `voxel_size_m` sets the completeness threshold (2
  /// voxels) and the margin around moving boxes (a voxel).
  std::map<std::string, MeshScores> scoreMeshes(const std::map<std::string, MeshToScore>& meshes,
                                                double voxel_size_m) const;
  /// The depth scores by method into the report.
  void writeDepthScores(RunReport& report) const;
  /// Why a ghost figure is absent, in words ("" when moving boxes exist).
  std::string noGhostsReason() const;

private:
  std::unique_ptr<synthetic::GroundTruth> truth_;
  std::map<std::string, DepthErrorAccumulator> all_, background_, foreground_;
  std::vector<Eigen::Vector3f> seen_surface_;  // ground-truth depth back-projected to the world
  std::vector<float> seen_depth_;              // the depth each was seen at
  pcl::PolygonMesh scene_;                     // gt/scene.ply
  std::optional<SurfaceClasses> classes_;      // gt/scene_classes.txt, when the dataset has it
  bool score_meshes_ = true;
};

} // namespace msf
