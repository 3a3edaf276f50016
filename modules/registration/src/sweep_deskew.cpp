#include <msf/registration/sweep_deskew.h>

#include <algorithm>
#include <cmath>

namespace msf {

namespace {

/// atan2 within 2e-8 rad (Abramowitz and Stegun 4.4.49 on [0, 1], then the octant), a third of
/// libm's time: it runs for each of a scan's 120000 returns, and 2e-8 rad of azimuth is
/// 3e-9 of a turn, a nanometre of deskewing.
double azimuth(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = std::max(ax, ay);
  if (big == 0.0)
    return 0.0;
  const double t = std::min(ax, ay) / big, t2 = t * t;
  double a = t * (0.9999993329 +
                  t2 * (-0.3332985605 +
                        t2 * (0.1994653599 +
                              t2 * (-0.1390853351 +
                                    t2 * (0.0964200441 + t2 * (-0.0559098861 + t2 * (0.0218612288 + t2 * -0.0040540580)))))));
  if (ay > ax)
    a = 0.5 * M_PI - a;
  if (x < 0.0)
    a = M_PI - a;
  return y < 0.0 ? -a : a;
}

} // namespace

PointList deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep) {
  PointList out;
  deskewSweep(points_sensor, motion_per_sweep, out);
  return out;
}

void deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep, PointList& out) {
  const Eigen::AngleAxisd rotation(motion_per_sweep.linear());
  // To first order in the rotation: a car turns a degree or two in a tenth of a second, and
  // half of that moves a point at 50 m by 2 mm less than the exact rotation would.
  const Eigen::Vector3d omega = rotation.angle() * rotation.axis();
  const Eigen::Vector3d translation = motion_per_sweep.translation();
  out.resize(points_sensor.size());
  for (std::size_t i = 0; i < points_sensor.size(); ++i) {
    const Eigen::Vector3d& p = points_sensor[i];
    // Time of the point in turns from the forward-facing instant: -0.5 (behind, first) .. 0.5.
    const double s = azimuth(p.y(), p.x()) * (0.5 / M_PI);
    out[i] = p + s * (omega.cross(p) + translation);
  }
}

} // namespace msf
