// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/evaluation/odometry_metrics.h>
#include <msf/evaluation/trajectory_plot.h>
#include <msf/io/image_io.h>
#include <msf/io/tum_poses.h>
#include <msf/io/world_frame.h>
#include <msf/pipeline/mesh_renderer.h>
#include <msf/pipeline/run_outputs.h>

#include <opencv2/core.hpp>

#include <filesystem>

namespace fs = std::filesystem;

namespace msf {

void writeMeshPreview(const std::string& dir, const TriangleMesh& mesh, const Calibration& calibration,
                      const Eigen::Isometry3d& T_world_cam0_first, RunReport& report) {
  const cv::Size size = calibration.requireImageSize();
  const cv::Mat above = MeshRenderer::renderFromAbove(mesh, -(T_world_cam0_first.linear().col(1)),
                                                      cv::Size(size.width, size.width / 2));
  const cv::Mat camera = MeshRenderer::render(mesh, T_world_cam0_first, calibration.fx(), calibration.fy(),
                                              calibration.cx(), calibration.cy(), size);
  cv::Mat preview;
  cv::vconcat(above, camera, preview);
  report.preview_file = "mesh_preview.png";
  writeImage((fs::path(dir) / report.preview_file).string(), preview);
}

void writeTrajectory(const std::string& dir, const PoseList& used, const std::vector<std::size_t>& frames,
                     const std::string& used_name, const FrameSource& source, const Eigen::Isometry3d& T_out_world,
                     RunReport& report) {
  if (used.empty())
    return;
  StampedPoses out{{}, transformPoses(used, T_out_world)};
  for (std::size_t k = 0; k < used.size(); ++k)
    out.timestamps.push_back(source.timestamp(frames[k]));
  saveOdometryPoses((fs::path(dir) / report.poses_file).string(), out.poses);
  saveTumPoses((fs::path(dir) / "poses_tum.txt").string(), out);
  const auto ofFrames = [&](const PoseList& all) {
    PoseList chosen;
    for (std::size_t k = 0; k < used.size() && k < frames.size(); ++k)
      chosen.push_back(all[frames[k]]);
    return chosen;
  };
  const bool separate_truth = &source.referencePoses() != &source.poses();
  std::vector<std::pair<std::string, PoseList>> trajectories{{used_name, used}};
  if (source.hasPoses() && used_name != "dataset")
    trajectories.emplace_back("dataset", ofFrames(source.poses()));
  if (separate_truth)
    trajectories.emplace_back("truth", ofFrames(source.referencePoses()));
  if (source.hasPoses() && (used_name != "dataset" || separate_truth) && used.size() > 1) {
    report.trajectory_metrics = evaluateOdometry(used, ofFrames(source.referencePoses()));
    report.has_trajectory_metrics = report.trajectory_metrics.path_length_m > 0.0;
    report.trajectory_reference = source.referencePosesName();
  }
  report.trajectory_plot_file = "trajectory.png";
  writeImage((fs::path(dir) / report.trajectory_plot_file).string(), plotTrajectoriesFromAbove(trajectories));
}

void summarizeMapEvaluation(const ReconstructionEvaluation& evaluation,
                            const std::map<std::string, SyntheticScoring::MeshScores>& mesh_scores,
                            const std::map<std::string, SeenThroughPieces>& seen_through,
                            RunReport::MapEvaluation& out) {
  out.frames = evaluation.frames();
  out.gt_pixels = evaluation.groundTruthPixels();
  const auto rows = evaluation.scores();
  for (const char* source : {"mesh", "fused", "mesh_lidar", "mesh_stereo", "mesh_paper", "paper"})
    for (const auto& score : rows)
      if (score.source == source) {
        RunReport::MapEvaluation::Row row;
        row.score = score;
        const auto it = mesh_scores.find(source);
        if (it != mesh_scores.end()) {
          row.has_accuracy = true;
          row.accuracy = it->second.accuracy;
          row.has_ghosts = it->second.has_ghosts;
          row.ghosts = it->second.ghosts;
          row.crumbs = it->second.crumbs;
          row.true_sky = it->second.true_sky;
          row.true_sky_sheets = it->second.true_sky_sheets;
          row.off_surface = it->second.off_surface;
        }
        const auto seen = seen_through.find(source);
        if (seen != seen_through.end()) {
          row.has_seen_through = true;
          row.seen_through = seen->second;
        }
        out.rows.push_back(row);
      }
}

} // namespace msf
