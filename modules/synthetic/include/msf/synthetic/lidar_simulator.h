// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/scene_snapshot.h>
#include <msf/synthetic/synthetic_config.h>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

namespace msf::synthetic {

/// A spinning LiDAR of the beams lidarBeamElevationsDeg gives (KITTI's HDL-64E by default,
/// an HDL-32E, or any list), each sweeping the azimuth from -pi to pi in
/// lidar_azimuth_step_deg steps. The scan is a snapshot at the frame's pose and time (no
/// motion of the sensor or of moving objects during the sweep), so it agrees exactly with
/// the camera's ground truth.
/// Points are written ring after ring, top laser first, each ring one sweep of rising
/// atan2(y, x): the ring split of protocol 2 (docs/design.md) finds exactly one ring a beam.
/// Each return: range + Gaussian noise, lost with probability lidar_dropout (and half the
/// time on glass), none from the sky or beyond lidar_max_range_m; intensity from the
/// surface's infrared reflectivity and incidence angle, in KITTI's 0..1 with 0.01 steps
/// (median ~0.3 as on KITTI's scans: road 0.3, markings 0.75, number plates 0.95).
class LidarSimulator {
public:
  explicit LidarSimulator(const SyntheticConfig& config);

  /// Elevation of each laser in degrees, ring order (highest first).
  const std::vector<double>& elevationsDeg() const { return elevations_deg_; }
  int ringCount() const { return static_cast<int>(elevations_deg_.size()); }
  int pointsPerRing() const { return steps_; }

  /// One scan in the Velodyne frame with the Velodyne at T_world_velo, of `scene` at its
  /// time; `frame_key` selects the noise (use the frame index).
  pcl::PointCloud<pcl::PointXYZI> scan(const SceneSnapshot& scene, const Eigen::Isometry3d& T_world_velo,
                                       std::uint64_t frame_key) const;

private:
  SyntheticConfig config_;
  std::vector<double> elevations_deg_;
  int steps_ = 0;
};

} // namespace msf::synthetic
