// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Geometry>

#include <cstddef>

namespace msf {

/// The correspondence distance of the next registration, from how wrong the constant-velocity
/// prediction has been (Vizzo et al., KISS-ICP, 2023: the threshold adapts to the motion
/// instead of being tuned per sensor and speed). A correction of the prediction by rotation
/// theta and translation t moves a point within max_range by up to |t| + max_range * theta;
/// sigma is the RMS of the corrections of at least min_correction, and the threshold is
/// 3 sigma. Smaller corrections are no samples: a prediction that was right says nothing
/// about how wrong the next one can be, and a threshold shrunk to the noise would lose the
/// map at the first jolt. Until a sample, the threshold is the initial one.
class AdaptiveThreshold {
public:
  AdaptiveThreshold(double initial_threshold_m, double min_correction_m, double max_range_m)
      : initial_(initial_threshold_m), min_correction_(min_correction_m), max_range_(max_range_m) {}

  /// `correction`: prediction^-1 * registered pose.
  void update(const Eigen::Isometry3d& correction);
  /// 3 sigma, or the initial threshold before any sample.
  double threshold() const;
  /// The robust kernel's scale: sigma.
  double sigma() const { return threshold() / 3.0; }
  std::size_t samples() const { return samples_; }

private:
  double initial_, min_correction_, max_range_;
  double sum_squares_ = 0.0;
  std::size_t samples_ = 0;
};

} // namespace msf
