// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/point_list.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace msf {

/// Motion compensation of a spinning LiDAR's sweep. The sensor turns counter-clockwise seen
/// from above (KITTI's HDL-64E) and measures each point at a time proportional to its
/// azimuth, one turn a frame; the scan's frame is the sensor's pose when it faced forward
/// (+x, where KITTI's cameras are triggered), half-way through the turn. Under a constant
/// motion `motion_per_sweep` (the sensor's pose change over one turn, T_previous^-1 T_current),
/// each point moves to where it would have been measured from that pose. At KITTI's 13 m per
/// second the sensor moves 1.3 m during a turn: a scan left as it is has the road behind the
/// car ~0.6 m off from the road ahead.
PointList deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep);
/// The same into `out` (its memory reused; not `points_sensor`).
void deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep, PointList& out);

/// deskewSweep of one point at a time (inline, for a loop that does more with each point,
/// such as VoxelDownsampler::downsampleScan): the same arithmetic, so the same points.
class SweepDeskew {
public:
  explicit SweepDeskew(const Eigen::Isometry3d& motion_per_sweep) {
    const Eigen::AngleAxisd rotation(motion_per_sweep.linear());
    // To first order in the rotation: a car turns a degree or two in a tenth of a second, and
    // half of that moves a point at 50 m by 2 mm less than the exact rotation would.
    omega_ = rotation.angle() * rotation.axis();
    translation_ = motion_per_sweep.translation();
  }

  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const {
    // Time of the point in turns from the forward-facing instant: -0.5 (behind, first) .. 0.5.
    const double s = azimuth(p.y(), p.x()) * (0.5 / M_PI);
    return p + s * (omega_.cross(p) + translation_);
  }

  /// atan2 within 2e-8 rad (Abramowitz and Stegun 4.4.49 on [0, 1], then the octant), a third
  /// of libm's time: it runs for each of a scan's 120000 returns, and 2e-8 rad of azimuth is
  /// 3e-9 of a turn, a nanometre of deskewing.
  static double azimuth(double y, double x) {
    const double ax = std::abs(x), ay = std::abs(y);
    const double big = std::max(ax, ay);
    if (big == 0.0)
      return 0.0;
    const double t = std::min(ax, ay) / big, t2 = t * t;
    double a =
        t * (0.9999993329 +
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

private:
  Eigen::Vector3d omega_, translation_;
};

} // namespace msf
