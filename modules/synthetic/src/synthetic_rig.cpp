// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/synthetic/kitti_rig.h>
#include <msf/synthetic/synthetic_rig.h>

#include <cmath>

namespace msf::synthetic {

namespace {

constexpr int kHdl64BlockLasers = 32;
constexpr double kHdl64UpperSpacingDeg = 1.0 / 3.0;
constexpr double kHdl64BlockGapDeg = 0.5;
constexpr int kHdl32Lasers = 32;
constexpr int kHdl32LevelBeam = 23; // the beams lie at whole multiples of 4/3 degree from it

/// KITTI's unit, highest first as its lasers are listed.
std::vector<double> hdl64eHighestFirst(double top, double bottom) {
  std::vector<double> e;
  const double upper_last = top - (kHdl64BlockLasers - 1) * kHdl64UpperSpacingDeg;
  const double lower_first = upper_last - kHdl64BlockGapDeg;
  for (int i = 0; i < kHdl64BlockLasers; ++i)
    e.push_back(top - i * kHdl64UpperSpacingDeg);
  for (int i = 0; i < kHdl64BlockLasers; ++i)
    e.push_back(lower_first + (bottom - lower_first) * i / (kHdl64BlockLasers - 1));
  return e;
}

/// Camera 0 to the LiDAR: x forward, y left, z up, 0.08 m above and 0.27 m behind it.
Eigen::Isometry3d levelLidarMount() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  T.translation() = Eigen::Vector3d(0.0, -0.08, -0.27);
  return T;
}

Calibration pinholeRig(const SyntheticConfig& c) {
  Calibration rig;
  rig.source = "synthetic pinhole rig (" + std::to_string(c.image_width_px) + "x" +
               std::to_string(c.image_height_px) + ", f " + std::to_string(c.focal_px) + " px, baseline " +
               std::to_string(c.baseline_m) + " m)";
  rig.image_size = cv::Size(c.image_width_px, c.image_height_px);
  const bool centred = c.principal_point_px.empty();
  const double cx = centred ? 0.5 * c.image_width_px : c.principal_point_px[0];
  const double cy = centred ? 0.5 * c.image_height_px : c.principal_point_px[1];
  Calibration::Projection left;
  left << c.focal_px, 0.0, cx, 0.0, 0.0, c.focal_px, cy, 0.0, 0.0, 0.0, 1.0, 0.0;
  Calibration::Projection right = left;
  right(0, 3) = -c.focal_px * c.baseline_m;
  rig.P = {left, right, left, right};
  rig.T_cam0_velo = levelLidarMount();
  return rig;
}

} // namespace

std::vector<double> lidarBeamElevationsDeg(const SyntheticConfig& config) {
  if (config.lidar_model == "beams")
    return config.lidar_beam_elevations_deg;
  std::vector<double> e;
  if (config.lidar_model == "hdl32e") {
    for (int i = 0; i < kHdl32Lasers; ++i) // as the data sheet lists them, to 0.01 degree
      e.push_back(std::round((i - kHdl32LevelBeam) * 400.0 / 3.0) / 100.0);
    return e;
  }
  e = hdl64eHighestFirst(config.lidar_upper_elevation_deg, config.lidar_lower_elevation_deg);
  return {e.rbegin(), e.rend()};
}

Calibration syntheticRig(const SyntheticConfig& config) {
  config.validateRig();
  Calibration rig = config.camera == "kitti" ? kittiRig() : pinholeRig(config);
  rig.lidar.beam_elevations_deg = lidarBeamElevationsDeg(config);
  rig.lidar.rings = static_cast<int>(rig.lidar.beam_elevations_deg.size());
  rig.lidar.sweeping = false;
  return rig;
}

void applyRig(const Calibration& rig, SyntheticConfig& config) {
  const cv::Size size = rig.requireImageSize();
  if (!rig.has_velodyne)
    throw InvalidInputError("rig '" + rig.source + "' has no lidar: a synthetic street needs its T_cam_lidar");
  if (std::fabs(rig.fx() - rig.fy()) > 1e-9 * rig.fx())
    throw InvalidInputError("rig '" + rig.source + "': fx " + std::to_string(rig.fx()) + " and fy " +
                            std::to_string(rig.fy()) + " differ; the synthetic cameras have square pixels");
  if (rig.lidar.rings > 0 && rig.lidar.beam_elevations_deg.empty())
    throw InvalidInputError("rig '" + rig.source + "': lidar.rings " + std::to_string(rig.lidar.rings) +
                            " without lidar.beam_elevations_deg; the simulated LiDAR needs its beams");
  config.camera = "pinhole";
  config.image_width_px = size.width;
  config.image_height_px = size.height;
  config.focal_px = rig.fx();
  config.principal_point_px = {rig.cx(), rig.cy()};
  config.baseline_m = rig.baselineGrey();
  if (!rig.lidar.beam_elevations_deg.empty()) {
    config.lidar_model = "beams";
    config.lidar_beam_elevations_deg = rig.lidar.beam_elevations_deg;
  }
  config.validateRig();
}

} // namespace msf::synthetic
