// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/registration/scan_to_map_icp.h>
#include <msf/registration/sweep_deskew.h>
#include <msf/registration/voxel_downsample.h>

#include <cmath>

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

Eigen::Isometry3d LidarOdometry::registerPoints(const PointList& points_sensor, const std::string& name,
                                                const Eigen::Isometry3d* measured_motion) {
  Stats stats;
  if (points_sensor.empty() && !measured_motion)
    throw InvalidInputError(name + ": no points (an empty scan, or one whose every return was NaN or infinite: "
                                   "the scan reader drops those)");
  const double frame_voxel = 0.5 * config_.voxel_size_m;
  // The measured motion, or constant velocity: the last motion again, in the sensor's frame;
  // the scan deskewed by it.
  const Eigen::Isometry3d motion = measured_motion   ? *measured_motion
                                   : poses_.size() > 1 ? poses_[poses_.size() - 2].inverse() * poses_.back()
                                                       : Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d prediction = poses_.empty() ? Eigen::Isometry3d::Identity() : poses_.back() * motion;
  // The returns in range, deskewed and downsampled in one pass over the scan (no copy of its
  // 120000 returns at each step).
  const SweepDeskew predicted(motion);
  stats.input_points =
      downsampler_.downsampleScan(points_sensor, config_.min_range_m, config_.max_range_m,
                                  sweeps_ && poses_.size() > 1 ? &predicted : nullptr, frame_voxel, frame_, &moments_);
  if (stats.input_points == 0 && !measured_motion)
    throw InvalidInputError(name + ": none of its " + std::to_string(points_sensor.size()) +
                            " points is a finite return between odometry.min_range_m " +
                            std::to_string(config_.min_range_m) + " and max_range_m " +
                            std::to_string(config_.max_range_m) + " m");
  const ScanConstraints constraints = checkConstraints(name, stats, measured_motion != nullptr);

  if (poses_.empty()) {
    if (sweeps_) // deskewed once the second scan tells the motion
      keepFirstReturns(points_sensor);
    return accept(Eigen::Isometry3d::Identity(), stats);
  }
  PosePrior prior;
  prior.T_world_sensor = prediction;
  prior.translation_sigma_m = config_.prior_translation_sigma_m;
  prior.rotation_sigma_rad = config_.prior_rotation_sigma_deg * M_PI / 180.0;
  Eigen::Isometry3d pose = align(points_sensor, name, prediction, measured_motion ? &prior : nullptr, stats);
  if (measured_motion)
    pose = keepPriorWhereFree(prediction, pose, constraints, config_.min_constraint);
  threshold_.update(prediction.inverse() * pose);
  return accept(pose, stats);
}

ScanConstraints LidarOdometry::checkConstraints(const std::string& name, Stats& stats, bool has_prior) const {
  const ScanConstraints constraints = analyzeConstraints(frame_, 2.0 * config_.voxel_size_m);
  stats.constraint = constraints.weakest();
  const int free = constraints.unconstrained(config_.min_constraint);
  if (free > 0 && !has_prior)
    throw InvalidInputError(name + ": its planes leave " + std::to_string(free) +
                            " of 6 degrees of freedom unconstrained (weakest: " + constraints.weakestDirection() +
                            ", " + std::to_string(constraints.weakest()) + " <= odometry.min_constraint " +
                            std::to_string(config_.min_constraint) + ", " + std::to_string(constraints.patches) +
                            " planar patches): a single plane or an empty scene cannot be registered");
  return constraints;
}

void LidarOdometry::keepFirstReturns(const PointList& points_sensor) {
  const double min2 = config_.min_range_m * config_.min_range_m, max2 = config_.max_range_m * config_.max_range_m;
  first_returns_.clear();
  for (const Eigen::Vector3d& p : points_sensor) {
    const double r2 = p.squaredNorm();
    if (r2 >= min2 && r2 <= max2 && p.allFinite())
      first_returns_.push_back(p);
  }
}

Eigen::Isometry3d LidarOdometry::align(const PointList& points_sensor, const std::string& name,
                                       const Eigen::Isometry3d& prediction, const PosePrior* prior, Stats& stats) {
  const double frame_voxel = 0.5 * config_.voxel_size_m, source_voxel = 1.5 * config_.voxel_size_m;
  const Eigen::Isometry3d last = poses_.back();
  IcpSettings icp;
  icp.max_correspondence_m = threshold_.threshold();
  icp.kernel_scale_m = threshold_.sigma();
  icp.max_iterations = config_.max_iterations;
  icp.convergence = config_.convergence;
  icp.point_to_plane = config_.point_to_plane;
  icp.prior = prior;
  // With one scan in the map, a voxel that is no plane holds a ring or two of it, which a
  // scan from a metre away sees alike: point-to-point pairs there hold the first
  // registration at no motion (the synthetic street: 1.1 m registered as 0.1 m). Planes do not.
  icp.planes_only = config_.point_to_plane && poses_.size() == 1;
  auto alignTo = [&](const LocalMap& map, const Eigen::Isometry3d& guess) {
    try {
      return alignScanToMap(source_, map, guess, icp, &neighbors_);
    } catch (const InvalidInputError& e) {
      throw InvalidInputError(name + ": " + e.what() + " (the scan does not overlap the local map)");
    }
  };
  downsampler_.downsample(frame_, source_voxel, source_);
  IcpResult result = alignTo(map_, prediction);
  if (sweeps_ && poses_.size() == 1) {
    // The motion is known now: the second scan, and the first one in the map, deskewed by it.
    const Eigen::Isometry3d estimated = last.inverse() * result.T_world_sensor;
    const SweepDeskew deskew(estimated);
    downsampler_.downsampleScan(points_sensor, config_.min_range_m, config_.max_range_m, &deskew, frame_voxel, frame_,
                                &moments_);
    std::vector<PointMoments> first_moments;
    const PointList first = voxelDownsample(deskewSweep(first_returns_, estimated), frame_voxel, &first_moments);
    LocalMap first_map(config_.voxel_size_m, config_.max_points_per_voxel);
    first_map.addScan(first, first_moments); // the first scan is the world frame
    downsampler_.downsample(frame_, source_voxel, source_);
    result = alignTo(first_map, result.T_world_sensor);
    map_ = std::move(first_map);
    first_returns_.clear();
  }
  stats.source_points = source_.size();
  stats.iterations = result.iterations;
  stats.searches = neighbors_.searches();
  stats.correspondences = result.correspondences;
  stats.threshold_m = icp.max_correspondence_m;
  return result.T_world_sensor;
}

Eigen::Isometry3d LidarOdometry::accept(const Eigen::Isometry3d& pose, Stats& stats) {
  stats.map_points_added = frame_.size();
  frame_world_.resize(frame_.size());
  for (std::size_t i = 0; i < frame_.size(); ++i) {
    frame_world_[i] = pose * frame_[i];
    moments_[i] = moments_[i].rotated(pose.linear());
  }
  map_.addScan(frame_world_, moments_);
  map_.removeFarFrom(pose.translation(), config_.max_range_m);
  stats.map_points = map_.size();
  poses_.push_back(pose);
  stats_ = stats;
  return pose;
}

Eigen::Isometry3d keepPriorWhereFree(const Eigen::Isometry3d& prior, const Eigen::Isometry3d& registered,
                                     const ScanConstraints& constraints, double min_constraint) {
  const int free = constraints.unconstrained(min_constraint);
  if (free == 0)
    return registered;
  if (constraints.patches == 0 || !(constraints.lever_m > 0.0))
    return prior;
  const Eigen::Isometry3d E = prior.inverse() * registered;
  const Eigen::AngleAxisd rotation(E.linear());
  Eigen::Matrix<double, 6, 1> e;
  e << E.translation(), rotation.angle() * constraints.lever_m * rotation.axis();
  for (int k = 0; k < free; ++k)
    e -= constraints.eigenvectors.col(k) * constraints.eigenvectors.col(k).dot(e);
  const Eigen::Vector3d w = e.tail<3>() / constraints.lever_m;
  Eigen::Isometry3d kept = Eigen::Isometry3d::Identity();
  if (w.norm() > 0.0)
    kept.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  kept.translation() = e.head<3>();
  return prior * kept;
}

LidarOdometry::Config resolveDeskew(LidarOdometry::Config config, const FrameSource& source) {
  if (config.deskew == "auto")
    config.deskew = source.calibration().lidar.sweeping ? "sweep" : "none";
  return config;
}

Eigen::Isometry3d cameraPose(const Eigen::Isometry3d& T_velo0_velo, const Eigen::Isometry3d& T_cam0_velo,
                             const Eigen::Isometry3d& T_world_cam0_first) {
  return T_world_cam0_first * T_cam0_velo * T_velo0_velo * T_cam0_velo.inverse();
}

} // namespace msf
