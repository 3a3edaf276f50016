// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/rig_geometry.h>

#include <cmath>

namespace msf {

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;
constexpr double kKittiFocalPx = 7.215377e+02;
constexpr double kKittiTopBeamDeg = 2.0, kKittiBottomBeamDeg = -24.9;
constexpr int kKittiBeams = 64;

double meanSpacingRad(const std::vector<double>& elevations_deg) {
  if (elevations_deg.size() < 2)
    return 0.0;
  return (elevations_deg.back() - elevations_deg.front()) * kDegree / static_cast<double>(elevations_deg.size() - 1);
}
} // namespace

RigGeometry RigGeometry::of(const Calibration& calibration) {
  RigGeometry g;
  g.focal_baseline = calibration.focalBaseline();
  g.rows_per_ring = calibration.fy() * meanSpacingRad(calibration.lidar.beam_elevations_deg);
  return g;
}

double RigGeometry::kittiRowsPerRing() {
  return kKittiFocalPx * (kKittiTopBeamDeg - kKittiBottomBeamDeg) * kDegree / (kKittiBeams - 1);
}

double RigGeometry::ringScale() const { return rows_per_ring > 0.0 ? rows_per_ring / kittiRowsPerRing() : 1.0; }

} // namespace msf
