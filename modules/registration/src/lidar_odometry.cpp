#include <msf/common/exceptions.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/registration/scan_to_map_icp.h>
#include <msf/registration/sweep_deskew.h>
#include <msf/registration/voxel_downsample.h>

namespace msf {

void LidarOdometry::Config::validate() const {
  checkKeyRanges(*this);
  if (!(min_range_m < max_range_m))
    throw ConfigError("odometry.min_range_m must be below max_range_m (" + configValue(max_range_m) + "), got " +
                      configValue(min_range_m));
}

LidarOdometry::LidarOdometry() : LidarOdometry(Config{}) {}

LidarOdometry::LidarOdometry(const Config& config)
    : config_((config.validate(), config)), map_(config.voxel_size_m, config.max_points_per_voxel),
      threshold_(config.initial_threshold_m, config.min_correction_m, config.max_range_m),
      sweeps_(config.deskew != "none") {}

Eigen::Isometry3d LidarOdometry::registerPoints(const PointList& points_sensor, const std::string& name) {
  Stats stats;
  if (points_sensor.empty())
    throw InvalidInputError(name + ": no points (an empty scan, or one whose every return was NaN or infinite: "
                                   "the scan reader drops those)");
  const double frame_voxel = 0.5 * config_.voxel_size_m, source_voxel = 1.5 * config_.voxel_size_m;
  // Constant velocity: the last motion again, in the sensor's frame; the scan deskewed by it.
  const Eigen::Isometry3d motion =
      poses_.size() > 1 ? poses_[poses_.size() - 2].inverse() * poses_.back() : Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d prediction = poses_.empty() ? Eigen::Isometry3d::Identity() : poses_.back() * motion;
  std::vector<PointMoments>& moments = moments_; // the returns each frame point stands for, for the map's planes
  PointList& frame = frame_;
  // The returns in range, deskewed and downsampled in one pass over the scan (no copy of its
  // 120000 returns at each step).
  const SweepDeskew predicted(motion);
  stats.input_points =
      downsampler_.downsampleScan(points_sensor, config_.min_range_m, config_.max_range_m,
                                  sweeps_ && poses_.size() > 1 ? &predicted : nullptr, frame_voxel, frame, &moments);
  if (stats.input_points == 0)
    throw InvalidInputError(name + ": none of its " + std::to_string(points_sensor.size()) +
                            " points is a finite return between odometry.min_range_m " +
                            std::to_string(config_.min_range_m) + " and max_range_m " +
                            std::to_string(config_.max_range_m) + " m");
  const ScanConstraints constraints = analyzeConstraints(frame, 2.0 * config_.voxel_size_m);
  stats.constraint = constraints.weakest();
  if (constraints.unconstrained(config_.min_constraint) > 0)
    throw InvalidInputError(name + ": its planes leave " + std::to_string(constraints.unconstrained(config_.min_constraint)) +
                            " of 6 degrees of freedom unconstrained (weakest: " + constraints.weakestDirection() +
                            ", " + std::to_string(constraints.weakest()) + " <= odometry.min_constraint " +
                            std::to_string(config_.min_constraint) + ", " + std::to_string(constraints.patches) +
                            " planar patches): a single plane or an empty scene cannot be registered");

  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (poses_.empty()) {
    if (sweeps_) { // deskewed once the second scan tells the motion
      const double min2 = config_.min_range_m * config_.min_range_m, max2 = config_.max_range_m * config_.max_range_m;
      first_returns_.clear();
      for (const Eigen::Vector3d& p : points_sensor) {
        const double r2 = p.squaredNorm();
        if (r2 >= min2 && r2 <= max2 && p.allFinite())
          first_returns_.push_back(p);
      }
    }
  } else {
    const Eigen::Isometry3d& last = poses_.back();
    IcpSettings icp;
    icp.max_correspondence_m = threshold_.threshold();
    icp.kernel_scale_m = threshold_.sigma();
    icp.max_iterations = config_.max_iterations;
    icp.convergence = config_.convergence;
    icp.point_to_plane = config_.point_to_plane;
    // With one scan in the map, a voxel that is no plane holds a ring or two of it, which a
    // scan from a metre away sees alike: point-to-point pairs there hold the first
    // registration at no motion (the synthetic street: 1.1 m registered as 0.1 m). Planes do not.
    icp.planes_only = config_.point_to_plane && poses_.size() == 1;
    auto align = [&](const PointList& source, const LocalMap& map, const Eigen::Isometry3d& guess) {
      try {
        return alignScanToMap(source, map, guess, icp, &neighbors_);
      } catch (const InvalidInputError& e) {
        throw InvalidInputError(name + ": " + e.what() + " (the scan does not overlap the local map)");
      }
    };
    PointList& source = source_;
    downsampler_.downsample(frame, source_voxel, source);
    IcpResult result = align(source, map_, prediction);
    if (sweeps_ && poses_.size() == 1) {
      // The motion is known now: the second scan, and the first one in the map, deskewed by it.
      const Eigen::Isometry3d estimated = last.inverse() * result.T_world_sensor;
      const SweepDeskew deskew(estimated);
      downsampler_.downsampleScan(points_sensor, config_.min_range_m, config_.max_range_m, &deskew, frame_voxel, frame,
                                  &moments);
      std::vector<PointMoments> first_moments;
      const PointList first = voxelDownsample(deskewSweep(first_returns_, estimated), frame_voxel, &first_moments);
      LocalMap first_map(config_.voxel_size_m, config_.max_points_per_voxel);
      first_map.addScan(first, first_moments); // the first scan is the world frame
      downsampler_.downsample(frame, source_voxel, source);
      result = align(source, first_map, result.T_world_sensor);
      map_ = std::move(first_map);
      first_returns_.clear();
    }
    pose = result.T_world_sensor;
    threshold_.update(prediction.inverse() * pose);
    stats.source_points = source.size();
    stats.iterations = result.iterations;
    stats.searches = neighbors_.searches();
    stats.searches = neighbors_.searches();
    stats.correspondences = result.correspondences;
    stats.threshold_m = icp.max_correspondence_m;
  }
  stats.map_points_added = frame.size();
  PointList& frame_world = frame_world_;
  frame_world.resize(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    frame_world[i] = pose * frame[i];
    moments[i] = moments[i].rotated(pose.linear());
  }
  map_.addScan(frame_world, moments);
  map_.removeFarFrom(pose.translation(), config_.max_range_m);
  stats.map_points = map_.size();
  poses_.push_back(pose);
  stats_ = stats;
  return pose;
}

LidarOdometry::Config resolveDeskew(LidarOdometry::Config config, const FrameSource& source) {
  if (config.deskew == "auto")
    config.deskew = source.sweepingScans() ? "sweep" : "none";
  return config;
}

Eigen::Isometry3d cameraPose(const Eigen::Isometry3d& T_velo0_velo, const Eigen::Isometry3d& T_cam0_velo,
                             const Eigen::Isometry3d& T_world_cam0_first) {
  return T_world_cam0_first * T_cam0_velo * T_velo0_velo * T_cam0_velo.inverse();
}

} // namespace msf
