// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/mesh_view_scoring.h>
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/scan_free_space.h>

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
  /// within_range split by whether a nearby frame's scan saw through the true return (see
  /// ReconstructionEvaluation::addScan): the surface stayed, or it left (an object that moved on).
  DepthMetrics lasting_within_range;
  DepthMetrics transient_within_range;
};

/// The small pieces of a mesh that the ground truth sees through: crumbs on real frames, where
/// no one knows where moving objects were.
struct SeenThroughPieces {
  std::size_t pieces = 0;        ///< connected pieces of the mesh
  std::size_t small_pieces = 0;  ///< of those, with fewer than max_triangles triangles
  std::size_t seen_through = 0;  ///< small pieces in front of the true depth (see seenThroughPieces)
  std::size_t triangles = 0;     ///< their triangles
  std::size_t max_triangles = 0; ///< what "small" means
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
/// Where the dataset does not say what moved (KITTI), the scans do: a true return that the scan
/// of a nearby frame saw through lay on a surface that left, and a map that holds what stayed is
/// scored there apart (addScan, the lasting and transient pixels).
///
/// addGroundTruth and scoreDepth may be called from different threads (the pipeline's
/// loading and integration threads); all calls are serialized by one lock. Once scans are given,
/// a frame's depth waits at its ground-truth pixels until the scans of the kScanWindow frames
/// after it have marked them (or scores() is asked), so that every source is split alike.
class ReconstructionEvaluation {
public:
  /// camera: of the ground truth (camera 0); focal_baseline: f B of the grey pair, for the
  /// disparities of D1; max_depth_m: the reconstruction's range. Throws InvalidInputError
  /// for an invalid camera or f B, ConfigError for a range that is not > 0.
  ReconstructionEvaluation(const PinholeCamera& camera, double focal_baseline, double max_depth_m,
                           const D1Threshold& d1 = {});

  /// Keeps the ground truth of `frame`: depth (CV_32FC1 of the camera's size; > 0 and finite
  /// = true depth) seen from T_world_cam, and optionally `moving` (CV_8UC1 of the same size,
  /// non-zero = a moving object). Throws InvalidInputError for a frame given twice, an image
  /// of the wrong type or size, or a pose that is not finite.
  void addGroundTruth(std::size_t frame, const Eigen::Isometry3d& T_world_cam, const cv::Mat& depth,
                      const cv::Mat& moving = cv::Mat());
  /// Frames whose scans test each other's ground truth: a frame's scan sees through the true
  /// returns of frames up to this many before and after it (a second of KITTI's: what moved
  /// has left, what stood is still in view).
  static constexpr std::size_t kScanWindow = 10;
  /// The free space of `frame`'s scan, the LiDAR at T_world_lidar: a true pixel of another frame
  /// within kScanWindow whose return lies in it, in front of the scan's returns around its
  /// direction by more than the scan's skew and D1's threshold (seen from the scan), is
  /// transient. Frames are given in order, each scan before its frame's depth is scored; the
  /// scans of the last kScanWindow are kept. An empty free space is ignored. Throws
  /// InvalidInputError for a pose that is not finite.
  void addScan(std::size_t frame, const Eigen::Isometry3d& T_world_lidar, const ScanFreeSpace& free_space);
  /// True once a scan was given: the rows' lasting and transient pixels mean something.
  bool splitsTransient() const;

  /// Scores `depth` (CV_32FC1 of the camera's size, metres, not > 0 = none) of `frame` as
  /// row `source`. Throws InvalidInputError for a frame without ground truth or a wrong image.
  void scoreDepth(const std::string& source, std::size_t frame, const cv::Mat& depth);
  /// Renders `mesh` at every frame's pose and scores it as row `source`.
  void scoreMesh(const std::string& source, const TriangleMesh& mesh);
  /// The same through `views`, whose renderings other scorers of the same frames share: each
  /// frame's view of the mesh `views` renders is scored as row `source`.
  void addViews(MeshViewScoring& views, const std::string& source);
  /// The pieces of `mesh` with fewer than `max_triangles` triangles that lie in front of the
  /// ground truth: a vertex is seen through when, at some frame, the true depth is known in the
  /// 3x3 pixels it projects to and all of it lies behind the vertex by more than D1's
  /// threshold (the held-out ring passed through it); a piece is, when more than half of its
  /// vertices that met ground truth were. Throws InvalidInputError when max_triangles is 0.
  SeenThroughPieces seenThroughPieces(const TriangleMesh& mesh, std::size_t max_triangles = 50) const;

  std::size_t frames() const;
  /// Ground-truth pixels kept over all frames (static and moving).
  std::size_t groundTruthPixels() const;
  double maxDepth() const { return max_depth_m_; }
  /// One row per source, in the order each was first scored.
  std::vector<ReconstructionScore> scores() const;

private:
  struct FrameTruth {
    Eigen::Isometry3d T_world_cam;
    /// v * width + u; the top bit marks a moving object, the next a transient return
    std::vector<std::uint32_t> pixels;
    std::vector<float> depth;
  };
  struct Scan {
    Eigen::Isometry3d T_lidar_world;
    ScanFreeSpace free_space;
  };
  /// Accumulators of one source (static all / within range, moving all / within range, lasting
  /// and transient within range), and its depth at the pixels of frames later scans may still mark.
  struct Row {
    std::string source;
    std::vector<DepthErrorAccumulator> errors;
    std::map<std::size_t, std::vector<float>> waiting;
  };
  Row& row(const std::string& source);
  /// Scores `depth` of `frame` into `row`, or keeps it at the truth's pixels while scans to come
  /// may still mark them.
  void score(Row& row, std::size_t frame, const FrameTruth& truth, const cv::Mat& depth);
  /// `depth` at the pixels of `truth`.
  std::vector<float> sample(const FrameTruth& truth, const cv::Mat& depth) const;
  /// Adds `estimates` (at the pixels of `truth`) to `errors`.
  void accumulate(std::vector<DepthErrorAccumulator>& errors, const FrameTruth& truth,
                  const std::vector<float>& estimates) const;
  /// Scores the waiting frames that no scan to come can mark any more.
  void scoreSettledFrames();
  /// Marks the pixels of `truth` that `scan`, of another frame, saw through.
  void markTransient(FrameTruth& truth, const Scan& scan) const;
  void checkImage(const cv::Mat& image, int type, const std::string& what) const;
  /// 2 when all true depth around p_cam's pixel lies behind it (D1), 1 when some does not, 0
  /// when it has none.
  std::uint8_t seenThrough(const Eigen::Vector3f& p_cam, const cv::Mat& truth_depth) const;

  PinholeCamera camera_;
  double focal_baseline_, max_depth_m_;
  D1Threshold d1_;
  mutable std::mutex mutex_;
  std::map<std::size_t, FrameTruth> frames_;
  std::map<std::size_t, Scan> scans_; ///< the last kScanWindow frames'
  bool splits_transient_ = false;
  std::size_t last_scan_ = 0;
  std::vector<Row> rows_;
};

} // namespace msf
