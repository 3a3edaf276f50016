// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/odometry_metrics.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

namespace {

/// The devkit's rotation error: the angle of R, acos clamped.
double rotationAngle(const Eigen::Isometry3d& T) {
  const double c = 0.5 * (T.linear().trace() - 1.0);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

/// First frame after `first` whose distance along the path exceeds the first's by `length`; -1 if none.
long lastFrameOfSegment(const std::vector<double>& distance, std::size_t first, double length) {
  for (std::size_t i = first; i < distance.size(); ++i)
    if (distance[i] > distance[first] + length)
      return static_cast<long>(i);
  return -1;
}

} // namespace

PoseList alignFirstPose(const PoseList& estimate, const PoseList& reference) {
  PoseList aligned;
  if (estimate.empty() || reference.empty())
    return aligned;
  const Eigen::Isometry3d T_align = reference.front() * estimate.front().inverse();
  aligned.reserve(estimate.size());
  for (const auto& T : estimate)
    aligned.push_back(T_align * T);
  return aligned;
}

OdometryMetrics evaluateOdometry(const PoseList& estimate, const PoseList& reference) {
  if (estimate.size() != reference.size())
    throw InvalidInputError("odometry evaluation: the estimate has " + std::to_string(estimate.size()) +
                            " poses and the reference " + std::to_string(reference.size()) + "; they must pair up");
  if (estimate.size() < 2)
    throw InvalidInputError("odometry evaluation: " + std::to_string(estimate.size()) +
                            " pose(s); a trajectory needs at least 2");
  OdometryMetrics m;
  m.poses = estimate.size();
  std::vector<double> distance(m.poses, 0.0);
  for (std::size_t i = 1; i < m.poses; ++i)
    distance[i] = distance[i - 1] + (reference[i].translation() - reference[i - 1].translation()).norm();
  m.path_length_m = distance.back();
  if (!(m.path_length_m > 0.0))
    throw InvalidInputError("odometry evaluation: the reference does not move (path length 0): drift per distance is undefined");

  // Segments (the devkit's calcSequenceErrors).
  std::size_t step = 10;
  for (double length = 100.0; length <= 800.0; length += 100.0)
    m.segment_lengths_m.push_back(length);
  if (m.path_length_m <= m.segment_lengths_m.front()) {
    m.devkit_lengths = false;
    m.segment_lengths_m.clear();
    for (int k = 1; k <= 7; ++k)
      m.segment_lengths_m.push_back(k * m.path_length_m / 8.0);
    step = 1;
  }
  double t_sum = 0.0, r_sum = 0.0;
  for (std::size_t first = 0; first < m.poses; first += step)
    for (double length : m.segment_lengths_m) {
      const long last = lastFrameOfSegment(distance, first, length);
      if (last < 0)
        continue;
      const auto l = static_cast<std::size_t>(last);
      const Eigen::Isometry3d delta_ref = reference[first].inverse() * reference[l];
      const Eigen::Isometry3d delta_est = estimate[first].inverse() * estimate[l];
      const Eigen::Isometry3d error = delta_est.inverse() * delta_ref;
      t_sum += error.translation().norm() / length;
      r_sum += rotationAngle(error) / length;
      ++m.segments;
    }
  if (m.segments > 0) {
    m.translation_error_pct = 100.0 * t_sum / static_cast<double>(m.segments);
    m.rotation_error_deg_per_m = (180.0 / M_PI) * r_sum / static_cast<double>(m.segments);
  }

  // ATE and end-point drift, the first poses aligned.
  const PoseList aligned = alignFirstPose(estimate, reference);
  double sum2 = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < m.poses; ++i) {
    const double e = (aligned[i].translation() - reference[i].translation()).norm();
    sum2 += e * e;
    sum += e;
    m.ate_max_m = std::max(m.ate_max_m, e);
  }
  m.ate_rmse_m = std::sqrt(sum2 / static_cast<double>(m.poses));
  m.ate_mean_m = sum / static_cast<double>(m.poses);
  m.end_drift_m = (aligned.back().translation() - reference.back().translation()).norm();
  m.end_drift_pct = 100.0 * m.end_drift_m / m.path_length_m;
  m.end_rotation_error_deg = (180.0 / M_PI) * rotationAngle(aligned.back().inverse() * reference.back());
  return m;
}

} // namespace msf
