// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/ins_error.h>

#include <array>
#include <cmath>

namespace msf::synthetic {

namespace {

constexpr std::array<double, 3> kPeriodsS{5.0, 11.0, 23.0};
constexpr std::uint64_t kInsPurpose = 0x1e5;

/// One axis's wander at time t: unit RMS over time, zero at t = 0.
double wander(double t, int seed, int axis) {
  double sum = 0.0;
  for (std::size_t j = 0; j < kPeriodsS.size(); ++j) {
    const double phase = 2.0 * M_PI * uniform01(hashKey(static_cast<std::uint64_t>(seed), kInsPurpose, axis, j));
    sum += std::sin(2.0 * M_PI * t / kPeriodsS[j] + phase) - std::sin(phase);
  }
  return sum * std::sqrt(2.0 / kPeriodsS.size()); // each sinusoid has RMS 1 / sqrt(2)
}

} // namespace

PoseList insPoses(const PoseList& truth, const SyntheticConfig& config) {
  PoseList measured;
  measured.reserve(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double t = static_cast<double>(i) / config.frame_rate_hz;
    const double heading = config.ins_heading_drift_deg_per_s * t * M_PI / 180.0;
    const Eigen::Vector3d offset(wander(t, config.seed, 0), 0.5 * wander(t, config.seed, 1), wander(t, config.seed, 2));
    Eigen::Isometry3d T = truth[i];
    T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitY()) * truth[i].linear();
    T.translation() += config.ins_position_error_m * offset;
    measured.push_back(T);
  }
  return measured;
}

} // namespace msf::synthetic
