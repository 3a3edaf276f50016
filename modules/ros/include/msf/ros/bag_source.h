// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/bag_options.h>
#include <msf/io/frame_source.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace msf {

/// A ROS 1 bag as a FrameSource: a LiDAR's sensor_msgs/PointCloud2, a rectified stereo pair of
/// sensor_msgs/Image with their CameraInfo, optionally a colour camera, and the poses from
/// /tf; kitti2bag's layout by default (BagOptions names other topics and frames).
///  - Frames: each scan with the left, right and colour images nearest to it in time, within
///    BagOptions::max_offset_s (matchFrames); what is left out is said in notes().
///  - Calibration: each camera's P from its CameraInfo (rectified, in the left camera's frame),
///    the image size from the left CameraInfo, and the LiDAR-to-camera extrinsic from tf (the
///    scan's frame to the left image's, /tf_static or /tf). A `rig` file (a KITTI calib.txt or
///    a rig YAML) replaces all of it; without one, a bag with no extrinsic is an error that
///    says to give one.
///  - Poses: T_world_cam0 from tf (BagOptions::world_frame to the left image's frame) at each
///    left image's stamp, when the bag has /tf; otherwise none (the engine's odometry).
/// Opening reads the header of every scan and image (the stamps, not the payloads' decoding)
/// and every tf and CameraInfo message; load() reads one frame's messages.
class BagSource : public FrameSource {
public:
  /// Throws IOError naming the file for a bag that cannot be read, InvalidInputError naming
  /// the topic (and the bag's topics) for a topic missing or of the wrong type, and
  /// CalibrationError naming what to give for a calibration the bag does not hold.
  explicit BagSource(const std::string& path, const BagOptions& options = {}, const std::string& rig = "");
  ~BagSource() override;
  BagSource(const BagSource&) = delete;
  BagSource& operator=(const BagSource&) = delete;

  const Calibration& calibration() const override { return calibration_; }
  std::size_t size() const override { return frames_.size(); }
  /// "000042": the frame's position among the bag's frames.
  std::string frameName(std::size_t i) const override;
  /// Seconds from the first frame's scan to frame i's, as load() stamps the frame.
  double timestamp(std::size_t i) const override { return static_cast<double>(scanStampNs(i) - scanStampNs(0)) / 1e9; }
  /// Thread-safe (the bag's reads are serialized). Throws InvalidInputError for an image whose
  /// size is not the calibration's or a message that cannot be converted.
  Frame load(std::size_t i, bool with_color = true) const override;
  const PoseList& poses() const override { return poses_; }
  std::string posesName() const override;
  std::string description() const override { return path_; }
  std::string scanName(std::size_t i) const override;
  bool hasColor() const override { return has_color_; }
  /// What the reader skipped or assumed: frames left out and why, a topic read under another name.
  std::vector<std::string> notes() const override { return notes_; }

  /// The options as used: the topics read (after kitti2bag's other image names) and the world frame.
  const BagOptions& options() const { return options_; }
  /// Stamp of frame i's scan and left image, nanoseconds since the epoch.
  std::int64_t scanStampNs(std::size_t i) const;
  std::int64_t leftStampNs(std::size_t i) const;

private:
  struct Bag; // the rosbag::Bag, its message index and tf buffer
  struct FrameMessages {
    std::size_t scan = 0, left = 0, right = 0;
    std::ptrdiff_t color = -1;
  };

  void resolveTopics();
  void readCalibration(const std::string& rig);
  /// BagOptions::sweeping_scans, when given, on the rig.
  void applySweeping();
  /// What the first scan tells of the LiDAR: its beams from the rings, when the rig lists none
  /// (beamElevationsFromRings), and a note when its points' times say one instant while the rig
  /// is taken as sweeping.
  void learnFromFirstScan();
  void matchAndPose();

  std::string path_;
  BagOptions options_;
  std::unique_ptr<Bag> bag_;
  Calibration calibration_;
  std::vector<FrameMessages> frames_;
  PoseList poses_;
  bool has_color_ = false;
  std::vector<std::string> notes_;
};

} // namespace msf
