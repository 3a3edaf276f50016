#include <msf/registration/sweep_deskew.h>

#include <cmath>

namespace msf {

PointList deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep) {
  const Eigen::AngleAxisd rotation(motion_per_sweep.linear());
  // To first order in the rotation: a car turns a degree or two in a tenth of a second, and
  // half of that moves a point at 50 m by 2 mm less than the exact rotation would.
  const Eigen::Vector3d omega = rotation.angle() * rotation.axis();
  const Eigen::Vector3d translation = motion_per_sweep.translation();
  PointList out;
  out.reserve(points_sensor.size());
  for (const Eigen::Vector3d& p : points_sensor) {
    // Time of the point in turns from the forward-facing instant: -0.5 (behind, first) .. 0.5.
    const double s = std::atan2(p.y(), p.x()) * (0.5 / M_PI);
    out.push_back(p + s * (omega.cross(p) + translation));
  }
  return out;
}

} // namespace msf
