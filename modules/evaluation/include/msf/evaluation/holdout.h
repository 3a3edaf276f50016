// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/fusion_bounds.h>
#include <msf/evaluation/fusion_loss.h>
#include <msf/evaluation/holdout_breakdown.h>
#include <msf/io/calibration.h>
#include <msf/io/sequence.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/ring_split.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace msf {

/// Evaluation protocol 2 (docs/design.md), ring hold-out on real scans: the rings with
/// id % modulo == heldout_remainder are projected into camera 0 as ground-truth depth; the
/// other rings are the only LiDAR input a method sees. Keys: sections `rings` and
/// `projection` (whose camera must be 0: disparities are those of the grey pair).
struct HoldoutConfig {
  RingSplitConfig rings;
  ProjectionConfig projection;
  D1Threshold d1;
};

/// What a method receives for one frame.
struct HoldoutInput {
  std::size_t frame = 0;                               ///< index in the sequence
  const Calibration* calibration = nullptr;            ///< of the sequence
  pcl::PointCloud<pcl::PointXYZI>::ConstPtr scan;      ///< input rings only, velodyne frame, file order
  cv::Mat left, right;                                 ///< grey rectified pair (cameras 0, 1)
  cv::Mat color;                                       ///< camera 2 when loaded, else empty
  /// The frame's pose from the sequence, when it has one: what places earlier frames' scans.
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
};

/// One frame split for the protocol: the method input and the ground truth.
struct HoldoutFrame {
  HoldoutInput input;
  cv::Mat gt_depth;            ///< CV_32FC1, camera 0, held-out returns (0 = none)
  cv::Mat input_depth;         ///< CV_32FC1, camera 0, the input rings' returns (0 = none)
  std::size_t heldout_points = 0;
  int ring_count = 0;          ///< ring ids in the scan (wraps + 1)
};

/// Splits a loaded frame. Throws ConfigError when the projection camera is not 0.
HoldoutFrame makeHoldoutFrame(const Frame& frame, const Calibration& calibration, const HoldoutConfig& config);

/// A method under test: input of one frame -> depth image of camera 0 (CV_32FC1, metres,
/// 0 = no estimate). It may keep state between frames (buffers), frames come in order.
using HoldoutMethod = std::function<cv::Mat(const HoldoutInput&)>;

/// One row of the comparison table.
struct HoldoutResult {
  std::string method;
  DepthMetrics metrics;        ///< pooled over the pixels of all frames
  double median_ms = 0;        ///< median time of one call, over the frames
  std::size_t frames = 0;
  std::vector<RegionMetrics> regions; ///< holdoutRegions' metrics, with setBreakdown(true)
  /// With addFusionBounds, for every method but the bounds' two inputs: where it is bad and
  /// an input right.
  std::optional<FusionLoss> lost_to_bound;
};

/// Runs named methods over frames of a sequence under protocol 2.
class HoldoutEvaluation {
public:
  explicit HoldoutEvaluation(const HoldoutConfig& config = {});

  /// Throws InvalidInputError when the name is taken or empty.
  void addMethod(const std::string& name, HoldoutMethod method);
  /// Also the rows bound_select and bound_blend (FusionBound) of the named methods' depths,
  /// after the methods' rows; their time is 0; and each other method's FusionLoss against
  /// the two (HoldoutResult::lost_to_bound). Throws InvalidInputError unless both names are
  /// methods already added, and different.
  void addFusionBounds(const std::string& first, const std::string& second);
  /// Load camera 2 for the methods that need colour (off by default: it costs a decode).
  void setLoadColor(bool load) { load_color_ = load; }
  /// Also pool the metrics of each of holdoutRegions (HoldoutResult::regions).
  void setBreakdown(bool breakdown) { breakdown_ = breakdown; }
  /// Called after each frame with (frames done, frames in all); e.g. to print progress.
  void setProgress(std::function<void(std::size_t, std::size_t)> progress) { progress_ = std::move(progress); }

  /// One result per method, in the order added. Every method sees every frame; the time of
  /// a call includes everything the method does from the raw input rings (projection too).
  /// Throws InvalidInputError naming a method whose output has the wrong size or type.
  std::vector<HoldoutResult> run(const Sequence& sequence, const std::vector<std::size_t>& frames) const;

private:
  HoldoutConfig config_;
  std::vector<std::pair<std::string, HoldoutMethod>> methods_;
  std::size_t bound_first_ = 0, bound_second_ = 0; ///< method indices, with bounds_
  bool bounds_ = false;
  bool load_color_ = false;
  bool breakdown_ = false;
  std::function<void(std::size_t, std::size_t)> progress_;
};

/// The table a user compares methods with, one row per method (fixed-width text).
std::string formatHoldoutTable(const std::vector<HoldoutResult>& results);
/// Rows of every method's regions (HoldoutResult::regions), one per method and region.
std::string formatHoldoutBreakdown(const std::vector<HoldoutResult>& results);
/// The same rows as CSV with a header line, written atomically. Throws IOError.
void writeHoldoutCsv(const std::string& path, const std::vector<HoldoutResult>& results);

} // namespace msf
