// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/persistence.hpp>

#include <iosfwd>
#include <string>
#include <vector>

namespace msf::synthetic {

/// Settings of the synthetic KITTI-format generator: the `synthetic` section of a YAML
/// config (config/synthetic.yaml), mirrored with defaults in code.
struct SyntheticConfig {
  std::string scene = "street";        ///< the only scene so far
  int frames = 10;                     ///< frames to generate (>= 1)
  int seed = 1;                        ///< everything random derives from it (>= 0)
  double speed_mps = 10.0;             ///< along the street
  double frame_rate_hz = 10.0;         ///< camera and LiDAR rate
  int supersampling = 2;               ///< samples per pixel along each image axis (1..4)
  double image_noise_sigma = 2.0;      ///< grey levels, Gaussian, per pixel and channel
  double lidar_range_noise_m = 0.02;   ///< Gaussian, along the beam
  double lidar_dropout = 0.02;         ///< probability that a return is lost [0, 1)
  double lidar_max_range_m = 120.0;
  double lidar_min_range_m = 1.0;
  double lidar_azimuth_step_deg = 0.18; ///< KITTI's files: ~2000 points a ring at 10 Hz
  double lidar_upper_elevation_deg = 2.0;   ///< hdl64e: highest of the 64 lasers
  double lidar_lower_elevation_deg = -24.9; ///< hdl64e: lowest
  /// hdl64e (KITTI's) | hdl32e (32 beams, -30.67..+10.67 deg) | beams (lidar_beam_elevations_deg)
  std::string lidar_model = "hdl64e";
  std::vector<double> lidar_beam_elevations_deg; ///< beams: one per ring, lowest first, rising
  /// kitti: KITTI's cameras (kittiRig) | pinhole: a grey pair of the keys below (colour = grey left)
  std::string camera = "kitti";
  int image_width_px = 640;            ///< pinhole
  int image_height_px = 480;           ///< pinhole
  double focal_px = 500.0;             ///< pinhole: fx = fy
  std::vector<double> principal_point_px; ///< pinhole: [cx, cy]; empty = the image's centre
  double baseline_m = 0.12;            ///< pinhole: the grey pair's
  double textureless_share = 0.2;      ///< share of building lots with blank walls [0, 1]
  double parked_car_share = 0.6;       ///< share of parking slots taken [0, 1]
  double mesh_max_edge_m = 1.0;        ///< triangle size of gt/scene.ply's flat faces
  // Moving cars (see addTraffic in traffic.h); 0 cars turns them off.
  int moving_cars_ahead = 1;            ///< cars driving ahead in the cameras' lane (0..10)
  int moving_cars_oncoming = 2;         ///< oncoming cars met in each group (0..20)
  double oncoming_car_speed_mps = 10.0; ///< their speed along the street, (0, 40]
  double oncoming_group_period_s = 4.0; ///< a group is met every this many seconds [1, 3600]
  /// Drive out, turn round across the road (kLoopTurnFrames frames) and drive back in the
  /// other lane to where the drive began: the second half revisits the first's street.
  bool loop = false;
  static constexpr int kLoopTurnFrames = 10;
  // The dataset's poses as a GPS/INS measures them (see insPoses in ins_error.h): poses/00.txt
  // then carries the error and gt/poses.txt the truth.
  bool ins_poses = false;
  double ins_heading_drift_deg_per_s = 0.3; ///< heading error grows at this rate from frame 0 [0, 10]
  double ins_position_error_m = 1.0;        ///< RMS of the position's smooth wander [0, 10]
  // The drive's place in a street shared with other drives (the same seed and street_length_m
  // give the same static world; the poses are in that world's frame).
  double start_m = 0.0;          ///< the drive starts this far along the street (world z)
  bool reverse = false;          ///< the drive heads -z in the other lane, from start_m back
  /// The street's length in metres (world z from 0); 0: to the farthest point of the drive.
  double street_length_m = 0.0;
  /// Whether the drive is placed otherwise than from the street's start, heading +z.
  bool placed() const { return start_m != 0.0 || reverse; }

  /// Overrides the keys present in `node` (a `synthetic` section), then validates.
  /// Throws ConfigError naming a key with a wrong type or value.
  void read(const cv::FileNode& node);
  /// Throws ConfigError naming the first key with a value out of range.
  void validate() const;
  /// The camera and LiDAR keys alone (validate calls it).
  void validateRig() const;
  void print(std::ostream& out) const;
};

} // namespace msf::synthetic
