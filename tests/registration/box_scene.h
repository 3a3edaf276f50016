// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A street of axis-aligned boxes (road, two kerbs, parked cars, posts) scanned by a spinning
// LiDAR: rays at fixed elevations and azimuths from the sensor's pose, so the pattern of
// points moves with the sensor (rings on the road), as a real scan's does.
#include <msf/registration/point_list.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace msf::test {

struct Box {
  Eigen::Vector3d low, high;
};

/// A street from x = -60 to 260: the road at z = 0 with kerbs, on both sides building fronts
/// of 4-10 m set back by 8-13 m (the steps and passages between them face along the street),
/// parked cars with gaps, and posts: every direction is constrained, as in a real street.
inline std::vector<Box> streetOfBoxes() {
  std::vector<Box> boxes;
  boxes.push_back({{-60, -30, -1}, {260, 30, 0}});     // road
  boxes.push_back({{-60, -30, 0}, {260, -5, 0.15}});   // kerbs and pavements
  boxes.push_back({{-60, 5, 0}, {260, 30, 0.15}});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const double side : {-1.0, 1.0}) {
    for (double x = -60; x < 260;) { // buildings, with passages between some
      const double length = 4.0 + 6.0 * u(rng), setback = 8.0 + 5.0 * u(rng), height = 4.0 + 8.0 * u(rng);
      const double y0 = side * setback, y1 = side * (setback + 8.0);
      boxes.push_back({{x, std::min(y0, y1), 0.15}, {x + length, std::max(y0, y1), height}});
      x += length + (u(rng) < 0.4 ? 1.5 + 3.0 * u(rng) : 0.0);
    }
    for (double x = -55; x < 255;) { // parked cars
      const double y = side * (5.6 + 0.6 * u(rng));
      boxes.push_back({{x, y - 0.9, 0.15}, {x + 4.2, y + 0.9, 1.55}});
      x += 4.2 + 1.0 + 5.0 * u(rng);
    }
    for (double x = -50 + 5 * u(rng); x < 255; x += 3.0 + 4.0 * u(rng)) // posts, trees, signs
      boxes.push_back({{x, side * 7.6 - 0.12, 0.15}, {x + 0.25, side * 7.6 + 0.13, 4.0}});
  }
  return boxes;
}

/// Distance along a ray to a box (slab test); infinity when it misses.
inline double rayBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Box& b) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dir[a]) < 1e-12) {
      if (origin[a] < b.low[a] || origin[a] > b.high[a])
        return std::numeric_limits<double>::infinity();
      continue;
    }
    double ta = (b.low[a] - origin[a]) / dir[a], tb = (b.high[a] - origin[a]) / dir[a];
    if (ta > tb)
      std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1)
      return std::numeric_limits<double>::infinity();
  }
  return t0 > 0.0 ? t0 : std::numeric_limits<double>::infinity();
}

/// A scan in the sensor's frame from T_world_sensor: `rings` lasers from +15 down to -15
/// degrees (an Ouster OS1-32's field), one return every `azimuth_step_deg`, ranges up to 80 m
/// with Gaussian noise. With
/// a `motion_per_sweep`, the sensor moves while it turns, as a spinning LiDAR's does (the
/// azimuth a is measured at a / 2 pi of the turn, from T_world_sensor * motion^(a / 2 pi)),
/// and each point is where the sensor saw it then: the sweep that deskewSweep undoes.
inline PointList scanBoxes(const std::vector<Box>& boxes, const Eigen::Isometry3d& T_world_sensor, unsigned seed,
                           double noise_m = 0.01, const Eigen::Isometry3d& motion_per_sweep = Eigen::Isometry3d::Identity(),
                           int rings = 32, double azimuth_step_deg = 0.2) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  const Eigen::AngleAxisd turn(motion_per_sweep.linear());
  PointList points;
  for (int r = 0; r < rings; ++r) {
    const double elevation = (15.0 - 30.0 * r / (rings - 1)) * M_PI / 180.0;
    for (double az = -180.0; az < 180.0; az += azimuth_step_deg) {
      const double a = az * M_PI / 180.0, s = a / (2.0 * M_PI);
      Eigen::Isometry3d T_now = T_world_sensor;
      T_now.linear() = T_world_sensor.linear() * Eigen::AngleAxisd(s * turn.angle(), turn.axis()).toRotationMatrix();
      T_now.translation() += T_world_sensor.linear() * (s * motion_per_sweep.translation());
      const Eigen::Vector3d dir_sensor(std::cos(elevation) * std::cos(a), std::cos(elevation) * std::sin(a),
                                       std::sin(elevation));
      const Eigen::Vector3d dir = T_now.linear() * dir_sensor;
      double best = std::numeric_limits<double>::infinity();
      for (const Box& b : boxes)
        best = std::min(best, rayBox(T_now.translation(), dir, b));
      if (best > 80.0)
        continue;
      Eigen::Vector3d hit = T_now.translation() + dir * (best + noise(rng));
      if (hit.z() < 0.16) // the road and pavements are not flat to the millimetre: a 3 cm swell
        hit.z() += 0.03 * std::sin(1.3 * hit.x()) * std::sin(0.9 * hit.y());
      points.push_back(T_now.inverse() * hit);
    }
  }
  return points;
}

/// The sensor 1.73 m above the road at x, heading along +x, turned by yaw (radians).
inline Eigen::Isometry3d sensorPose(double x, double y = 0.0, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 1.73);
  return T;
}

} // namespace msf::test
