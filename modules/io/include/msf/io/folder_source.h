// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>

#include <map>
#include <string>
#include <vector>

namespace msf {

/// A dataset folder a user makes from any recording (the generic layout):
///
///   DIR/rig.yaml              the rig (rig_file.h), unless one is given
///   DIR/lidar/NNNNNN.bin      one scan a frame: .bin (KITTI), .pcd or .ply (x y z, optional
///                             intensity, ring, time)
///   DIR/left/NNNNNN.png       the rectified left camera: PNG or JPEG, 8 or 16 bit, grey or colour
///   DIR/right/NNNNNN.png      the rectified right camera, the same way
///   DIR/color/NNNNNN.png      optional: the colour camera (else a colour left image colours)
///   DIR/timestamps.txt        optional: seconds, line i for frame i (else 10 Hz)
///   DIR/poses.txt             optional: T_world_cam0, KITTI's 12 numbers with line i for
///                             frame i, or TUM's "t tx ty tz qx qy qz qw" matched by time
///
/// Frames are the numbered left images; frame NNNNNN is line NNNNNN of the text files (by its
/// number, not its place in the listing, so a gap in the numbering takes no other frame's
/// line). Files that are not frames (hidden ones, a README) are ignored.
class FolderSource : public FrameSource {
public:
  /// `rig`: a calibration or rig file to use instead of DIR/rig.yaml. Throws IOError naming
  /// the folder, file or frame when the layout is incomplete (a frame without its scan or
  /// right image, fewer lines than frames), CalibrationError for a bad rig.
  explicit FolderSource(const std::string& dir, const std::string& rig = "");

  /// Whether `dir` has the generic layout's folders (left/, right/, lidar/).
  static bool looksLikeOne(const std::string& dir);

  const Calibration& calibration() const override { return calibration_; }
  std::size_t size() const override { return frames_.size(); }
  std::string frameName(std::size_t i) const override {
    checkIndex(i);
    return frames_[i].name;
  }
  Frame load(std::size_t i, bool with_color = true) const override;
  pcl::PointCloud<pcl::PointXYZI>::Ptr loadScan(std::size_t i) const override;
  const PoseList& poses() const override { return poses_; }
  std::string posesName() const override { return "poses file '" + poses_file_ + "'"; }
  std::string description() const override { return dir_; }
  double timestamp(std::size_t i) const override {
    checkIndex(i);
    return timestamps_[i] - timestamps_.front();
  }
  std::string scanName(std::size_t i) const override {
    checkIndex(i);
    return "scan '" + frames_[i].scan + "'";
  }
  bool hasColor() const override { return has_color_; }
  std::vector<std::string> notes() const override { return notes_; }

private:
  struct FrameFiles {
    std::string name;
    std::size_t number = 0;
    std::string scan, left, right, color;
  };
  void findFrames();
  void checkIndex(std::size_t i) const;
  /// A scan file's points as a frame's scan: in the LiDAR's frame, stamped with frame i's time.
  pcl::PointCloud<pcl::PointXYZI>::Ptr frameScan(pcl::PointCloud<pcl::PointXYZI>&& points, std::size_t i) const;
  void readTimes();
  void readPoses();
  /// The LiDAR's beams from the first scan's rings, when the rig lists none (beamElevationsFromRings).
  void beamsFromFirstScan();

  std::string dir_, poses_file_;
  Calibration calibration_;
  std::vector<FrameFiles> frames_;
  std::vector<double> timestamps_;
  PoseList poses_;
  bool has_color_ = false;
  std::vector<std::string> notes_;
};

} // namespace msf
