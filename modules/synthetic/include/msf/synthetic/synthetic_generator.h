// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/poses.h>
#include <msf/io/surface_classes.h>
#include <msf/synthetic/camera_renderer.h>
#include <msf/synthetic/lidar_simulator.h>
#include <msf/synthetic/moving_box.h>
#include <msf/synthetic/scene.h>
#include <msf/synthetic/scene_snapshot.h>
#include <msf/synthetic/synthetic_config.h>

#include <opencv2/core/mat.hpp>
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace msf::synthetic {

/// Everything of one synthetic frame, in memory.
struct SyntheticFrame {
  cv::Mat images[4];  ///< cameras 0, 1: grey CV_8UC1; 2, 3: BGR CV_8UC3 (rectified) or empty
  pcl::PointCloud<pcl::PointXYZI> scan; ///< Velodyne frame, ring after ring
  cv::Mat depth;      ///< camera 0, CV_32F metres, 0 = no ground truth (sky, beyond 255 m)
  cv::Mat disparity;  ///< grey pair, CV_32F pixels (f B / depth), 0 where depth is 0
  cv::Mat objects;    ///< camera 0, CV_8U: 0 background, 1..255 foreground instance
  cv::Mat moving;     ///< camera 0, CV_8U: 255 where the pixel sees a moving object, else 0
};

/// The synthetic KITTI-format generator: a rig (syntheticRig: KITTI's by default) driving down a street
/// (buildStreetScene, with its moving cars) along streetTrajectory, rendered by
/// CameraRenderer and LidarSimulator at each frame's time. Deterministic: one seed, one
/// byte-identical dataset.
class SyntheticGenerator {
public:
  /// Builds the trajectory and the scene; throws ConfigError for an invalid config.
  explicit SyntheticGenerator(const SyntheticConfig& config);

  const SyntheticConfig& config() const { return config_; }
  const Calibration& calibration() const { return calibration_; }
  const PoseList& poses() const { return poses_; }
  const Scene& scene() const { return scene_; }
  /// The scene at frame i's time, i / frame_rate_hz. Throws InvalidInputError when i is out
  /// of range.
  SceneSnapshot sceneAt(std::size_t i) const;
  /// The oriented boxes of the moving objects present at every frame, frame by frame
  /// (gt/moving_objects.txt).
  std::vector<MovingBox> movingBoxes() const;
  const CameraRenderer& renderer() const { return renderer_; }
  const LidarSimulator& lidar() const { return lidar_; }
  std::size_t size() const { return poses_.size(); }

  /// Renders frame i; `with_color` false skips cameras 2 and 3 (left empty). Throws
  /// InvalidInputError when i is out of range.
  SyntheticFrame renderFrame(std::size_t i, bool with_color = true) const;

  /// The true static surface (see sceneMesh in scene_mesh.h), without the moving objects.
  pcl::PolygonMesh mesh(SurfaceClasses* classes = nullptr) const;

  /// Called after each written frame with its index, the seconds it took (from its start to
  /// the next frame's, and any wait for its files: they are written while the next frame
  /// renders) and its number of LiDAR points.
  using Progress = std::function<void(std::size_t frame, double seconds, std::size_t points)>;

  /// Writes the dataset under `root` (see docs/usage.md, "Data layouts": KITTI odometry layout plus gt/) as an
  /// OutputFolder: the tree is written into a hidden folder beside `root` and moved into
  /// place at the end, so a failure (or an exception from `progress`) leaves `root` as it
  /// was. `root` may be absent, empty, or a dataset written before (replaced); anything else
  /// is refused with an IOError naming it.
  void writeDataset(const std::string& root, const Progress& progress = {}) const;

private:
  /// The sequence's calibration, rig file, times and poses (the INS-like ones with the truth in gt).
  void writeSequenceFiles(const std::filesystem::path& seq, const std::filesystem::path& poses,
                          const std::filesystem::path& gt) const;
  /// The ground truth beside the frames: the config, a README, the scene's mesh and classes, the moving boxes.
  void writeGroundTruthFiles(const std::filesystem::path& gt) const;
  /// Each frame's images, scan and ground-truth images.
  void writeFrames(const std::filesystem::path& seq, const std::filesystem::path& gt, const Progress& progress) const;

  SyntheticConfig config_;
  Calibration calibration_;
  PoseList poses_;
  Scene scene_;
  CameraRenderer renderer_;
  LidarSimulator lidar_;
};

} // namespace msf::synthetic
