// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/registration/sweep_deskew.h>

namespace msf {

PointList deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep) {
  PointList out;
  deskewSweep(points_sensor, motion_per_sweep, out);
  return out;
}

void deskewSweep(const PointList& points_sensor, const Eigen::Isometry3d& motion_per_sweep, PointList& out) {
  const SweepDeskew deskew(motion_per_sweep);
  out.resize(points_sensor.size());
  for (std::size_t i = 0; i < points_sensor.size(); ++i)
    out[i] = deskew(points_sensor[i]);
}

} // namespace msf
