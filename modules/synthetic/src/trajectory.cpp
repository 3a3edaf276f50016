// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/scene.h>
#include <msf/synthetic/trajectory.h>

#include <cmath>

namespace msf::synthetic {

namespace {
constexpr double kSwayAmplitudeM = 0.4;
constexpr double kSwayWavelengthM = 150.0;
constexpr double kTwoPi = 6.283185307179586;
/// The path laid out from the street's start carried to the drive's place (unchanged, bit for
/// bit, for a drive from the start).
PoseList placed(const SyntheticConfig& config, PoseList poses) {
  if (!config.placed())
    return poses;
  const Eigen::Isometry3d T_world_drive = driveTransform(config);
  for (Eigen::Isometry3d& T : poses)
    T = T_world_drive * T;
  return poses;
}
} // namespace

int loopOutFrames(const SyntheticConfig& config) {
  return config.loop ? (config.frames - SyntheticConfig::kLoopTurnFrames) / 2 : config.frames;
}

PoseList streetTrajectory(const SyntheticConfig& config) {
  PoseList poses;
  const double step = config.speed_mps / config.frame_rate_hz;
  const int out = loopOutFrames(config);
  for (int i = 0; i < out; ++i) {
    const double z = step * i;
    const double phase = kTwoPi * z / kSwayWavelengthM;
    const double x = kSwayAmplitudeM * (1.0 - std::cos(phase));
    const double slope = kSwayAmplitudeM * kTwoPi / kSwayWavelengthM * std::sin(phase);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    // Heading about the vertical (camera y) axis: forward (0, 0, 1) becomes (sin, 0, cos).
    T.linear() = Eigen::AngleAxisd(std::atan(slope), Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, 0.0, z);
    poses.push_back(T);
  }
  if (!config.loop)
    return placed(config, std::move(poses));
  // The turn: a half circle to the left, from the right-hand lane to the other one (a lane
  // apart), the heading along it; then back along the other lane, without sway.
  const Eigen::Vector3d start = poses.back().translation();
  const double radius = 0.5 * StreetLayout().lane_width_m;
  const Eigen::Vector3d centre = start - Eigen::Vector3d(radius, 0, 0);
  const int turn = SyntheticConfig::kLoopTurnFrames;
  for (int k = 1; k <= turn; ++k) {
    const double a = M_PI * k / (turn + 1);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = centre + radius * Eigen::Vector3d(std::cos(a), 0, std::sin(a));
    poses.push_back(T);
  }
  const Eigen::Vector3d back = centre - Eigen::Vector3d(radius, 0, 0);
  for (int j = 0; static_cast<int>(poses.size()) < config.frames; ++j) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = back - Eigen::Vector3d(0, 0, step * j);
    poses.push_back(T);
  }
  return placed(config, std::move(poses));
}

Eigen::Isometry3d driveTransform(const SyntheticConfig& config) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().z() = config.start_m;
  if (config.reverse) {
    // Turned about the vertical through the road's axis: the right-hand lane becomes the left.
    T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation().x() = 2.0 * StreetLayout().road_center_x;
  }
  return T;
}

std::vector<double> frameTimes(const SyntheticConfig& config) {
  std::vector<double> t(static_cast<std::size_t>(config.frames));
  for (int i = 0; i < config.frames; ++i)
    t[static_cast<std::size_t>(i)] = i / config.frame_rate_hz;
  return t;
}

} // namespace msf::synthetic
