// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace msf {

/// One row of evaluation protocol 4: a depth source scored at the ground-truth pixels of
/// every frame. The static pixels are what a map should hold; a moving object's are not
/// part of it, and are scored apart.
struct ReconstructionScore {
  std::string source;          ///< "mesh", "fused", "mesh_lidar", "mesh_stereo", ...
  DepthMetrics all;            ///< every static ground-truth pixel
  DepthMetrics within_range;   ///< those whose true depth is within the reconstruction's range
  DepthMetrics moving_all;     ///< ground-truth pixels on moving objects (none without a moving mask)
  DepthMetrics moving_within_range;
};

/// Evaluation protocol 4 (docs/design.md): the reconstruction against ground truth it never saw.
/// The ground truth of each frame (protocol 2's held-out rings projected into camera 0, or a
/// synthetic sequence's exact depth) is kept as the list of its pixels, not as images, so a
/// long sequence stays small; per-frame depth images (the fused depth) are scored at those
/// pixels as they come, and after the run the mesh is rendered into the camera at every
/// frame's pose (MeshRasterizer: the first surface along each pixel's ray) and scored at the
/// same pixels, with protocol 2's metrics (DepthErrorAccumulator). A mesh that holds what
/// the frames saw comes close to the per-frame depth; ghosts, specks and holes show at once.
/// Pixels are split by whether their true depth is within the reconstruction's range
/// (tsdf_integrator.max_depth_m: the map holds nothing farther) and whether they are on a
/// moving object.
///
/// addGroundTruth and scoreDepth may be called from different threads (the pipeline's
/// loading and integration threads); all calls are serialized by one lock.
class ReconstructionEvaluation {
public:
  /// camera: of the ground truth (camera 0); focal_baseline: f B of the grey pair, for the
  /// disparities of D1; max_depth_m: the reconstruction's range. Throws InvalidInputError
  /// for an invalid camera or f B, ConfigError for a range that is not > 0.
  ReconstructionEvaluation(const PinholeCamera& camera, double focal_baseline, double max_depth_m,
                           const D1Threshold& d1 = {});

  /// The near plane of the mesh render (MeshRasterizer::setNearPlane).
  void setNearPlane(float near_m);

  /// Keeps the ground truth of `frame`: depth (CV_32FC1 of the camera's size; > 0 and finite
  /// = true depth) seen from T_world_cam, and optionally `moving` (CV_8UC1 of the same size,
  /// non-zero = a moving object). Throws InvalidInputError for a frame given twice, an image
  /// of the wrong type or size, or a pose that is not finite.
  void addGroundTruth(std::size_t frame, const Eigen::Isometry3d& T_world_cam, const cv::Mat& depth,
                      const cv::Mat& moving = cv::Mat());
  /// Scores `depth` (CV_32FC1 of the camera's size, metres, not > 0 = none) of `frame` as
  /// row `source`. Throws InvalidInputError for a frame without ground truth or a wrong image.
  void scoreDepth(const std::string& source, std::size_t frame, const cv::Mat& depth);
  /// Renders `mesh` at every frame's pose and scores it as row `source`.
  void scoreMesh(const std::string& source, const TriangleMesh& mesh);

  std::size_t frames() const;
  /// Ground-truth pixels kept over all frames (static and moving).
  std::size_t groundTruthPixels() const;
  double maxDepth() const { return max_depth_m_; }
  /// One row per source, in the order each was first scored.
  std::vector<ReconstructionScore> scores() const;

private:
  struct FrameTruth {
    Eigen::Isometry3d T_world_cam;
    std::vector<std::uint32_t> pixels; ///< v * width + u; the top bit marks a moving object
    std::vector<float> depth;
  };
  /// Accumulators of one source: static all / within range, moving all / within range.
  struct Row {
    std::string source;
    DepthErrorAccumulator errors[4];
  };
  Row& row(const std::string& source);
  void score(Row& row, const FrameTruth& truth, const cv::Mat& depth) const;
  void checkImage(const cv::Mat& image, int type, const std::string& what) const;

  PinholeCamera camera_;
  double focal_baseline_, max_depth_m_;
  D1Threshold d1_;
  mutable std::mutex mutex_;
  std::map<std::size_t, FrameTruth> frames_;
  std::vector<Row> rows_;
  MeshRasterizer rasterizer_;
  cv::Mat rendered_;
};

} // namespace msf
