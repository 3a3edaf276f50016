#pragma once
#include <msf/registration/point_list.h>

#include <Eigen/Geometry>

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

} // namespace msf
