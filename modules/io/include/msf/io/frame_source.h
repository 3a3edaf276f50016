// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/poses.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>
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

/// One frame of a rig, everything in memory: what the reconstruction engine is fed.
struct Frame {
  std::size_t index = 0;         ///< position in its source (0-based)
  double timestamp = 0.0;        ///< seconds from the source's first frame
  pcl::PointCloud<pcl::PointXYZI>::Ptr scan; ///< the LiDAR's points in its own frame, in the order it sent them
  /// Optional per point of `scan`: its ring (beam) id; empty = derived from the order (azimuth wraps).
  std::vector<std::uint16_t> point_ring;
  /// Optional per point of `scan`: seconds from the sweep's start; empty = derived from the azimuth.
  std::vector<float> point_time_s;
  cv::Mat left;                  ///< camera 0, grey CV_8UC1, rectified
  cv::Mat right;                 ///< camera 1, grey CV_8UC1, rectified
  cv::Mat color;                 ///< camera 2, BGR CV_8UC3, rectified; empty if absent
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
};

/// Throws InvalidInputError naming the frame and what does not fit the rig, so that the engine
/// refuses a frame before it changes any state: no scan or one without a point, per-point rings
/// or times of another count than the scan's points, a grey image missing, not 8-bit grey
/// (CV_8UC1) or not of the calibration's size (when it has one), a colour image not 8-bit BGR
/// (CV_8UC3) or of another size, a time that is not finite, a pose that is not rigid.
void checkFrame(const Frame& frame, const Calibration& calibration);

/// `frame`, or `copy` made of it with each image that is a view into a larger one (a cv::Mat
/// ROI) copied whole: OpenCV's filters read past a view's edge into the image it was cut from,
/// so a view would not give its copy's depth. The engine takes every frame through it.
const Frame& withWholeImages(const Frame& frame, Frame& copy);

/// Where frames come from: a dataset folder, a bag, a program. Readers of every layout (KITTI
/// odometry and raw, synthetic, a generic folder with a rig file, a ROS bag) give the engine
/// the same Frame, so a new reader touches no stage.
class FrameSource {
public:
  virtual ~FrameSource() = default;

  /// The rig: cameras, LiDAR extrinsic, image size.
  virtual const Calibration& calibration() const = 0;
  virtual std::size_t size() const = 0;
  /// The frame's name in outputs and messages ("000042").
  virtual std::string frameName(std::size_t i) const = 0;
  /// Loads frame i (scan, images and, when the source has them, its pose); `with_color` false
  /// skips the colour camera. Safe to call from another thread than the one that made the
  /// source. Throws IOError naming a missing or malformed file.
  virtual Frame load(std::size_t i, bool with_color = true) const = 0;
  /// Frame i's scan alone, as load() gives it (Frame::scan), without reading its images: for
  /// what reads every frame's scan before a run (the memory prediction). Throws as load() does.
  virtual pcl::PointCloud<pcl::PointXYZI>::Ptr loadScan(std::size_t i) const { return load(i, false).scan; }

  /// Frame i's time, seconds from the source's first frame (Frame::timestamp), without loading it.
  virtual double timestamp(std::size_t i) const = 0;
  /// The source's own poses T_world_cam0, one per frame, or none.
  virtual const PoseList& poses() const;
  bool hasPoses() const { return !poses().empty(); }
  /// Where poses() come from, in words ("the odometry ground truth").
  virtual std::string posesName() const { return "the dataset's poses"; }
  /// Whether poses() are a GPS/INS's measurement (KITTI raw's OXTS), which the scans can
  /// correct, rather than a ground truth: msf_reconstruct refines them by default.
  virtual bool posesAreMeasured() const { return false; }
  /// The poses a trajectory is scored against (protocol 5): the true ones when the source
  /// knows them apart from poses() (a synthetic drive with INS-like poses), else poses().
  virtual const PoseList& referencePoses() const { return poses(); }
  /// Where referencePoses() come from, in words.
  virtual std::string referencePosesName() const { return posesName(); }
  /// The source in words for messages and reports: its folder or file.
  virtual std::string description() const = 0;
  /// Frame i's scan in words for messages ("scan '.../000042.bin'").
  virtual std::string scanName(std::size_t i) const { return "the scan of frame " + frameName(i); }
  /// Whether frames carry a colour image (camera 2).
  virtual bool hasColor() const { return false; }
  /// Folder of synthetic ground truth, "" when there is none.
  virtual std::string groundTruthDir() const { return {}; }
  /// What the reader skipped or assumed, one line each, for the tool to print (a bag's frames
  /// left out for want of an image, say).
  virtual std::vector<std::string> notes() const { return {}; }

  /// Indices of the frames whose numbers (frameNumber of their names, else their index) lie in
  /// the range; throws InvalidInputError when it selects no frame or goes beyond the last.
  std::vector<std::size_t> indices(const FrameRange& range) const;
};

/// A frame's number from its name ("000042" -> 42); -1 for a name that is not all digits
/// (a stray file: "README", "000042 (copy)").
long long frameNumber(const std::string& name);

} // namespace msf
