// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>

#include <cstddef>
#include <string>
#include <vector>

namespace msf {

/// A KITTI sequence on disk, detected from the folder:
///  - odometry: `sequences/XX/{image_0,image_1,image_2,velodyne,calib.txt,times.txt}` with
///    poses in `../../poses/XX.txt` when present, and the calibration from a rig file
///    `rig.yaml` beside calib.txt when there is one; the folder may also be the dataset root
///    holding exactly one `sequences/XX` (as msf_synth writes; its `gt/poses.txt`, when
///    present, is the truth that INS-like poses in `poses/XX.txt` err from);
///  - raw drive: `YYYY_MM_DD_drive_NNNN_sync/{image_00..03/data,velodyne_points/data,oxts}`
///    with the calibration in the date folder above it; poses from OXTS.
class Sequence : public FrameSource {
public:
  enum class Layout { Odometry, Raw };

  /// Throws IOError naming the folder when it is neither layout.
  /// `calibration`: a calibration or rig file to use instead of the dataset's own ("" = its own).
  explicit Sequence(const std::string& dir, const std::string& calibration = "");

  Layout layout() const { return layout_; }
  const std::string& directory() const { return dir_; }
  const Calibration& calibration() const override { return calibration_; }
  std::size_t size() const override { return frame_names_.size(); }
  const PoseList& poses() const override { return poses_; }
  /// Where poses() come from, in words: "the synthetic ground truth", "the synthetic INS",
  /// "OXTS (GPS/IMU)" or "the odometry ground truth" (whether or not there are any).
  std::string posesName() const override;
  /// A raw drive's OXTS, and a synthetic drive's INS-like poses (msf_synth -ins_poses: the
  /// truth is then gt/poses.txt).
  bool posesAreMeasured() const override;
  /// gt/poses.txt of a synthetic drive with INS-like poses, else poses().
  const PoseList& referencePoses() const override { return true_poses_.empty() ? poses_ : true_poses_; }
  std::string referencePosesName() const override;
  /// Folder of synthetic ground truth (`<root>/gt`), "" when there is none.
  std::string groundTruthDir() const override { return gt_dir_; }
  /// File stem of a frame ("000042" or "0000000042").
  std::string frameName(std::size_t i) const override {
    checkIndex(i);
    return frame_names_[i];
  }
  std::string description() const override { return dir_; }
  double timestamp(std::size_t i) const override;
  std::string scanName(std::size_t i) const override { return "scan '" + scanPath(i) + "'"; }
  bool hasColor() const override;

  std::string scanPath(std::size_t i) const;
  /// camera 0..3
  std::string imagePath(int camera, std::size_t i) const;

  /// Loads scan, images and pose of frame i; throws IOError naming a missing file.
  /// Set `with_color` false to skip reading camera 2.
  Frame load(std::size_t i, bool with_color = true) const override;
  pcl::PointCloud<pcl::PointXYZI>::Ptr loadScan(std::size_t i) const override;

private:
  void checkIndex(std::size_t i) const;

  Layout layout_ = Layout::Odometry;
  std::string dir_, gt_dir_;
  Calibration calibration_;
  std::vector<std::string> frame_names_;
  std::vector<double> timestamps_;
  PoseList poses_;
  PoseList true_poses_;  // gt/poses.txt, when poses_ are a synthetic INS's
};

} // namespace msf
