#include <msf/synthetic/trajectory.h>

#include <cmath>

namespace msf::synthetic {

namespace {
constexpr double kSwayAmplitudeM = 0.4;
constexpr double kSwayWavelengthM = 150.0;
constexpr double kTwoPi = 6.283185307179586;
} // namespace

PoseList streetTrajectory(const SyntheticConfig& config) {
  PoseList poses;
  const double step = config.speed_mps / config.frame_rate_hz;
  for (int i = 0; i < config.frames; ++i) {
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
  return poses;
}

std::vector<double> frameTimes(const SyntheticConfig& config) {
  std::vector<double> t(static_cast<std::size_t>(config.frames));
  for (int i = 0; i < config.frames; ++i)
    t[static_cast<std::size_t>(i)] = i / config.frame_rate_hz;
  return t;
}

} // namespace msf::synthetic
