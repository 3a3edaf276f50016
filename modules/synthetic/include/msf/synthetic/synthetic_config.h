// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <string>
#include <vector>

namespace msf::synthetic {

/// Settings of the synthetic KITTI-format generator: section `synthetic` of a config file.
struct SyntheticConfig {
  static constexpr const char* kSection = "synthetic";
  static constexpr const char* kAbout =
      "msf_synth: a synthetic street seen by KITTI's rig, in KITTI's odometry layout, with exact ground truth";
  std::string scene = "street";
  int frames = 10;
  int seed = 1;
  double speed_mps = 10.0;
  double frame_rate_hz = 10.0;
  int supersampling = 2;
  double image_noise_sigma = 2.0;
  std::string sky = "pale";
  double lidar_range_noise_m = 0.02;
  double lidar_dropout = 0.02;
  double lidar_max_range_m = 120.0;
  double lidar_min_range_m = 1.0;
  double lidar_azimuth_step_deg = 0.18; ///< KITTI's files: ~2000 points a ring at 10 Hz
  double lidar_upper_elevation_deg = 2.0;
  double lidar_lower_elevation_deg = -24.9;
  std::string lidar_model = "hdl64e";
  std::vector<double> lidar_beam_elevations_deg;
  std::string camera = "kitti";
  int image_width_px = 640;
  int image_height_px = 480;
  double focal_px = 500.0;
  std::vector<double> principal_point_px;
  double baseline_m = 0.12;
  double textureless_share = 0.2;
  double parked_car_share = 0.6;
  double mesh_max_edge_m = 1.0;
  // Moving cars (see addTraffic in traffic.h); 0 cars turns them off.
  int moving_cars_ahead = 1;
  int moving_cars_oncoming = 2;
  double oncoming_car_speed_mps = 10.0;
  double oncoming_group_period_s = 4.0;
  bool loop = false;
  static constexpr int kLoopTurnFrames = 10;
  // The dataset's poses as a GPS/INS measures them (see insPoses in ins_error.h): poses/00.txt
  // then carries the error and gt/poses.txt the truth.
  bool ins_poses = false;
  double ins_heading_drift_deg_per_s = 0.3;
  double ins_position_error_m = 1.0;
  // The drive's place in a street shared with other drives (the same seed and street_length_m
  // give the same static world; the poses are in that world's frame).
  double start_m = 0.0;
  bool reverse = false;
  double street_length_m = 0.0;
  /// Whether the drive is placed otherwise than from the street's start, heading +z.
  bool placed() const { return start_m != 0.0 || reverse; }

  template <class Keys>
  void keys(Keys& k) {
    k("scene", scene, {"street"}, "the scene generated");
    k("frames", frames, between(1, 999999), "frames to generate");
    k("seed", seed, atLeast(0), "everything random derives from it");
    k("speed_mps", speed_mps, between(0, 40), "the cameras' speed along the street, m/s");
    k("frame_rate_hz", frame_rate_hz, Range{0, 100, true, false}, "camera and LiDAR rate, Hz");
    k("supersampling", supersampling, between(1, 4), "samples per pixel along each image axis");
    k("image_noise_sigma", image_noise_sigma, between(0, 50), "Gaussian image noise per pixel and channel, grey levels");
    k("sky", sky, {"pale", "kitti"},
      "pale: a smooth pale blue that stereo matches | kitti: KITTI's overexposed sky, clipped to a flat white "
      "near the horizon and in soft clouds, against which SGBM smears the crowns");
    k("lidar_range_noise_m", lidar_range_noise_m, between(0, 1), "Gaussian LiDAR noise along the beam, m");
    k("lidar_dropout", lidar_dropout, Range{0, 1, false, true}, "probability that a return is lost");
    k("lidar_max_range_m", lidar_max_range_m, Range{0, 250, true, false},
      "farthest return, m (above lidar_min_range_m; the depth PNG's limit is 256 m)");
    k("lidar_min_range_m", lidar_min_range_m, above(0), "nearest return, m");
    k("lidar_azimuth_step_deg", lidar_azimuth_step_deg, between(0.01, 5), "azimuth between two returns of a ring, deg");
    k("lidar_upper_elevation_deg", lidar_upper_elevation_deg, Range{-60, 30},
      "hdl64e: elevation of the highest of the 64 lasers, deg");
    k("lidar_lower_elevation_deg", lidar_lower_elevation_deg, Range{-60, 30},
      "hdl64e: elevation of the lowest, deg (more than 11 below the highest: the upper block spans 10.33)");
    k("lidar_model", lidar_model, {"hdl64e", "hdl32e", "beams"},
      "the LiDAR: KITTI's hdl64e, a 32-beam hdl32e (-30.67..+10.67 deg), or the beams of lidar_beam_elevations_deg");
    k("lidar_beam_elevations_deg", lidar_beam_elevations_deg, Range{-90, 90, true, true},
      "lidar_model beams: one elevation per ring (1..1024), lowest first, rising, deg");
    k("camera", camera, {"kitti", "pinhole"},
      "the cameras: KITTI's, or a grey pair of the pinhole keys below (the colour camera the grey left one)");
    k("image_width_px", image_width_px, between(16, 8192), "pinhole: image width, px");
    k("image_height_px", image_height_px, between(16, 8192), "pinhole: image height, px");
    k("focal_px", focal_px, between(1, 100000), "pinhole: focal length fx = fy, px");
    k("principal_point_px", principal_point_px, anyNumber(), "pinhole: [cx, cy], px ([]: the image's centre)");
    k("baseline_m", baseline_m, Range{0, 10, true, false}, "pinhole: the grey pair's baseline, m");
    k("textureless_share", textureless_share, between(0, 1), "share of building lots with blank walls");
    k("parked_car_share", parked_car_share, between(0, 1), "share of parking slots taken");
    k("mesh_max_edge_m", mesh_max_edge_m, between(0.05, 20), "triangle size of gt/scene.ply's flat faces, m");
    k("moving_cars_ahead", moving_cars_ahead, between(0, 10), "cars driving ahead in the cameras' lane");
    k("moving_cars_oncoming", moving_cars_oncoming, between(0, 20), "oncoming cars met in each group");
    k("oncoming_car_speed_mps", oncoming_car_speed_mps, Range{0, 40, true, false},
      "their speed along the street, m/s");
    k("oncoming_group_period_s", oncoming_group_period_s, between(1, 3600), "a group is met every this many seconds");
    k("loop", loop,
      "drive out, turn round across the road (10 frames) and drive back in the other lane to where the drive began");
    k("ins_poses", ins_poses,
      "poses/00.txt as a GPS/INS measures the drive (the error below), gt/poses.txt the true poses");
    k("ins_heading_drift_deg_per_s", ins_heading_drift_deg_per_s, between(0, 10),
      "ins_poses: the heading error grows at this rate from frame 0, deg/s");
    k("ins_position_error_m", ins_position_error_m, between(0, 10),
      "ins_poses: RMS of the position's smooth wander, m");
    k("start_m", start_m, between(0, 5000), "the drive starts this far along the street (world z), m");
    k("reverse", reverse, "the drive heads -z in the other lane, from start_m back");
    k("street_length_m", street_length_m, between(0, 5000),
      "the street's length from world z 0, m (0: to the farthest point of the drive); drives of the same seed "
      "and length share the static world");
  }
  /// Throws ConfigError naming the first key with a value out of range.
  void validate() const;
  /// The same, the camera and LiDAR keys' checks between keys alone after the ranges (what a
  /// rig made from the config needs).
  void validateRig() const;
};

} // namespace msf::synthetic
