// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/poses.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace msf {

/// Inclusive frame range "a:b" ("3:" to the end, "5" a single frame).
struct FrameRange {
  int first = 0;
  int last = -1; ///< -1: to the end
  /// Parses "a:b", "a:", ":b" or "a"; throws InvalidInputError naming the text.
  static FrameRange parse(const std::string& text);
};

/// One frame of a sequence, everything in memory.
struct Frame {
  std::size_t index = 0;         ///< position in the sequence (0-based file index)
  double timestamp = 0.0;        ///< seconds from the first frame
  pcl::PointCloud<pcl::PointXYZI>::Ptr scan; ///< velodyne frame, file order
  cv::Mat left;                  ///< camera 0, grey CV_8UC1, rectified
  cv::Mat right;                 ///< camera 1, grey CV_8UC1, rectified
  cv::Mat color;                 ///< camera 2, BGR CV_8UC3, rectified; empty if absent
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
};

/// A KITTI sequence on disk, detected from the folder:
///  - odometry: `sequences/XX/{image_0,image_1,image_2,velodyne,calib.txt,times.txt}` with
///    poses in `../../poses/XX.txt` when present; the folder may also be the dataset root
///    holding exactly one `sequences/XX` (as msf_synth writes);
///  - raw drive: `YYYY_MM_DD_drive_NNNN_sync/{image_00..03/data,velodyne_points/data,oxts}`
///    with the calibration in the date folder above it; poses from OXTS.
class Sequence {
public:
  enum class Layout { Odometry, Raw };

  /// Throws IOError naming the folder when it is neither layout.
  explicit Sequence(const std::string& dir);

  Layout layout() const { return layout_; }
  const std::string& directory() const { return dir_; }
  const Calibration& calibration() const { return calibration_; }
  std::size_t size() const { return frame_names_.size(); }
  bool hasPoses() const { return !poses_.empty(); }
  const PoseList& poses() const { return poses_; }
  /// Where poses() come from, in words: "the synthetic ground truth", "OXTS (GPS/IMU)" or
  /// "the odometry ground truth" (whether or not there are any).
  std::string posesName() const;
  /// Folder of synthetic ground truth (`<root>/gt`), "" when there is none.
  const std::string& groundTruthDir() const { return gt_dir_; }
  /// File stem of a frame ("000042" or "0000000042").
  const std::string& frameName(std::size_t i) const { return frame_names_.at(i); }

  std::string scanPath(std::size_t i) const;
  /// camera 0..3
  std::string imagePath(int camera, std::size_t i) const;

  /// Loads scan, images and pose of frame i; throws IOError naming a missing file.
  /// Set `with_color` false to skip reading camera 2.
  Frame load(std::size_t i, bool with_color = true) const;

  /// Indices of a range, clamped to the sequence; throws InvalidInputError when empty.
  std::vector<std::size_t> indices(const FrameRange& range) const;

private:
  Layout layout_ = Layout::Odometry;
  std::string dir_, gt_dir_;
  Calibration calibration_;
  std::vector<std::string> frame_names_;
  std::vector<double> timestamps_;
  PoseList poses_;
};

} // namespace msf
