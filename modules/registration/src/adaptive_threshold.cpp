// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/registration/adaptive_threshold.h>

#include <cmath>

namespace msf {

void AdaptiveThreshold::update(const Eigen::Isometry3d& correction) {
  const double angle = Eigen::AngleAxisd(correction.linear()).angle();
  const double e = correction.translation().norm() + 2.0 * max_range_ * std::sin(0.5 * angle); // chord at max_range
  if (e < min_correction_)
    return;
  sum_squares_ += e * e;
  ++samples_;
}

double AdaptiveThreshold::threshold() const {
  if (samples_ == 0)
    return initial_;
  return 3.0 * std::sqrt(sum_squares_ / static_cast<double>(samples_));
}

} // namespace msf
