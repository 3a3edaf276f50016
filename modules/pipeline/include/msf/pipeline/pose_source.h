#pragma once
#include <msf/io/sequence.h>
#include <msf/registration/lidar_odometry.h>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// Where a reconstruction's poses come from (msf_reconstruct -poses): the dataset's own, a
/// KITTI poses file, or LiDAR odometry estimated as the frames are loaded. A file's poses are
/// set by apply() in Pipeline::setFrameFilter, after the frame's other changes; the odometry
/// runs in Pipeline::setPoseEstimator, on a thread of its own beside the depth stages, and sees
/// the scan after the filter (the ring hold-out: the odometry sees only the scan the pipeline
/// sees). Either way the rest of the pipeline does not know where a pose came from.
class PoseSource {
public:
  enum class Kind { Dataset, File, Estimated };

  /// `option`: "dataset", "estimate" or the path of a poses file whose line i is frame i;
  /// "" is "dataset" when the sequence has poses, else "estimate". The estimate starts at
  /// the dataset's pose of the first frame when there is one (its map is then in the same
  /// world as the ground truth), else at the identity. Throws InvalidInputError naming the
  /// option when "dataset" has no poses or the file has no line for one of `frames`, and
  /// IOError for a malformed file.
  PoseSource(const std::string& option, const Sequence& sequence, const std::vector<std::size_t>& frames,
             const LidarOdometry::Config& odometry);
  ~PoseSource();

  /// Sets the frame's pose from a file (nothing for the dataset's, which Sequence::load set, or
  /// for an estimate, which estimate() gives).
  void apply(Frame& frame) const;
  /// The odometry's pose of the frame's scan. Frames in order: it tracks from one to the next.
  /// Throws what LidarOdometry throws, naming the frame's scan; InvalidInputError unless Estimated.
  Eigen::Isometry3d estimate(const Frame& frame);

  /// The poses T_world_cam0 of `frames` when they are known before the run (the dataset's or a
  /// file's), in order; empty for estimated ones, which exist only as the frames are tracked.
  PoseList knownPoses(const std::vector<std::size_t>& frames) const;

  Kind kind() const { return kind_; }
  /// In words, for the report: "the dataset's: ...", "file '...'" or "estimated (LiDAR odometry)".
  const std::string& description() const { return description_; }
  /// Milliseconds the odometry took for each frame applied (empty unless estimated).
  const std::vector<double>& estimateMs() const { return estimate_ms_; }

private:
  Kind kind_ = Kind::Dataset;
  std::string description_;
  const Sequence& sequence_;
  PoseList file_poses_;
  Eigen::Isometry3d T_world_cam0_first_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<LidarOdometry> odometry_;
  std::vector<double> estimate_ms_;
};

} // namespace msf
