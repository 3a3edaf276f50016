// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/synthetic/synthetic_config.h>

#include <charconv>
#include <ostream>
#include <sstream>

namespace msf::synthetic {

void SyntheticConfig::read(const cv::FileNode& node) {
  readKey(node, "scene", scene);
  readKey(node, "frames", frames);
  readKey(node, "seed", seed);
  readKey(node, "speed_mps", speed_mps);
  readKey(node, "frame_rate_hz", frame_rate_hz);
  readKey(node, "supersampling", supersampling);
  readKey(node, "image_noise_sigma", image_noise_sigma);
  readKey(node, "lidar_range_noise_m", lidar_range_noise_m);
  readKey(node, "lidar_dropout", lidar_dropout);
  readKey(node, "lidar_max_range_m", lidar_max_range_m);
  readKey(node, "lidar_min_range_m", lidar_min_range_m);
  readKey(node, "lidar_azimuth_step_deg", lidar_azimuth_step_deg);
  readKey(node, "lidar_upper_elevation_deg", lidar_upper_elevation_deg);
  readKey(node, "lidar_lower_elevation_deg", lidar_lower_elevation_deg);
  readKey(node, "lidar_model", lidar_model);
  readKey(node, "lidar_beam_elevations_deg", lidar_beam_elevations_deg);
  readKey(node, "camera", camera);
  readKey(node, "image_width_px", image_width_px);
  readKey(node, "image_height_px", image_height_px);
  readKey(node, "focal_px", focal_px);
  readKey(node, "principal_point_px", principal_point_px);
  readKey(node, "baseline_m", baseline_m);
  readKey(node, "textureless_share", textureless_share);
  readKey(node, "parked_car_share", parked_car_share);
  readKey(node, "mesh_max_edge_m", mesh_max_edge_m);
  readKey(node, "moving_cars_ahead", moving_cars_ahead);
  readKey(node, "moving_cars_oncoming", moving_cars_oncoming);
  readKey(node, "oncoming_car_speed_mps", oncoming_car_speed_mps);
  readKey(node, "oncoming_group_period_s", oncoming_group_period_s);
  readKey(node, "loop", loop);
  readKey(node, "ins_poses", ins_poses);
  readKey(node, "ins_heading_drift_deg_per_s", ins_heading_drift_deg_per_s);
  readKey(node, "ins_position_error_m", ins_position_error_m);
  readKey(node, "start_m", start_m);
  readKey(node, "reverse", reverse);
  readKey(node, "street_length_m", street_length_m);
  validate();
}

namespace {
template <typename T>
void require(bool ok, const char* key, T value, const char* rule) {
  if (ok)
    return;
  std::ostringstream msg;
  msg << "config key 'synthetic." << key << "' = " << value << " " << rule;
  throw ConfigError(msg.str());
}
} // namespace

void SyntheticConfig::validate() const {
  require(scene == "street", "scene", scene, "is unknown (known scenes: street)");
  require(frames >= 1 && frames <= 999999, "frames", frames, "must be in 1..999999");
  require(seed >= 0, "seed", seed, "must be >= 0");
  require(speed_mps >= 0.0 && speed_mps <= 40.0, "speed_mps", speed_mps, "must be in 0..40");
  require(frame_rate_hz > 0.0 && frame_rate_hz <= 100.0, "frame_rate_hz", frame_rate_hz, "must be in (0, 100]");
  require(supersampling >= 1 && supersampling <= 4, "supersampling", supersampling, "must be in 1..4");
  require(image_noise_sigma >= 0.0 && image_noise_sigma <= 50.0, "image_noise_sigma", image_noise_sigma,
          "must be in 0..50");
  require(lidar_range_noise_m >= 0.0 && lidar_range_noise_m <= 1.0, "lidar_range_noise_m", lidar_range_noise_m,
          "must be in 0..1");
  require(lidar_dropout >= 0.0 && lidar_dropout < 1.0, "lidar_dropout", lidar_dropout, "must be in [0, 1)");
  require(lidar_min_range_m > 0.0, "lidar_min_range_m", lidar_min_range_m, "must be > 0");
  require(lidar_max_range_m > lidar_min_range_m && lidar_max_range_m <= 250.0, "lidar_max_range_m",
          lidar_max_range_m, "must be above lidar_min_range_m and at most 250 (the depth PNG's limit is 256 m)");
  require(lidar_azimuth_step_deg >= 0.01 && lidar_azimuth_step_deg <= 5.0, "lidar_azimuth_step_deg",
          lidar_azimuth_step_deg, "must be in 0.01..5");
  require(lidar_upper_elevation_deg <= 30.0, "lidar_upper_elevation_deg", lidar_upper_elevation_deg,
          "must be at most 30");
  require(lidar_lower_elevation_deg >= -60.0 && lidar_lower_elevation_deg < lidar_upper_elevation_deg - 11.0,
          "lidar_lower_elevation_deg", lidar_lower_elevation_deg,
          "must be >= -60 and more than 11 below lidar_upper_elevation_deg (the upper block spans 10.33)");
  validateRig();
  require(textureless_share >= 0.0 && textureless_share <= 1.0, "textureless_share", textureless_share,
          "must be in 0..1");
  require(parked_car_share >= 0.0 && parked_car_share <= 1.0, "parked_car_share", parked_car_share,
          "must be in 0..1");
  require(mesh_max_edge_m >= 0.05 && mesh_max_edge_m <= 20.0, "mesh_max_edge_m", mesh_max_edge_m,
          "must be in 0.05..20");
  require(moving_cars_ahead >= 0 && moving_cars_ahead <= 10, "moving_cars_ahead", moving_cars_ahead,
          "must be in 0..10");
  require(moving_cars_oncoming >= 0 && moving_cars_oncoming <= 20, "moving_cars_oncoming", moving_cars_oncoming,
          "must be in 0..20");
  require(oncoming_car_speed_mps > 0.0 && oncoming_car_speed_mps <= 40.0, "oncoming_car_speed_mps",
          oncoming_car_speed_mps, "must be in (0, 40]");
  require(oncoming_group_period_s >= 1.0 && oncoming_group_period_s <= 3600.0, "oncoming_group_period_s",
          oncoming_group_period_s, "must be in 1..3600");
  require(!loop || frames >= kLoopTurnFrames + 2, "frames", frames,
          "must be >= 12 for a loop (out, the turn of 10 frames, back)");
  require(ins_heading_drift_deg_per_s >= 0.0 && ins_heading_drift_deg_per_s <= 10.0, "ins_heading_drift_deg_per_s",
          ins_heading_drift_deg_per_s, "must be in 0..10");
  require(ins_position_error_m >= 0.0 && ins_position_error_m <= 10.0, "ins_position_error_m", ins_position_error_m,
          "must be in 0..10");
  require(start_m >= 0.0 && start_m <= 5000.0, "start_m", start_m, "must be in 0..5000");
  require(street_length_m >= 0.0 && street_length_m <= 5000.0, "street_length_m", street_length_m,
          "must be in 0..5000 (0: as far as the drive goes)");
}

void SyntheticConfig::validateRig() const {
  require(lidar_model == "hdl64e" || lidar_model == "hdl32e" || lidar_model == "beams", "lidar_model", lidar_model,
          "is unknown (known: hdl64e, hdl32e, beams)");
  const std::vector<double>& e = lidar_beam_elevations_deg;
  require(lidar_model != "beams" || (!e.empty() && e.size() <= 1024), "lidar_beam_elevations_deg",
          std::to_string(e.size()) + " beams", "must hold 1..1024 elevations for lidar_model beams");
  for (std::size_t i = 0; i < e.size(); ++i) {
    require(e[i] > -90.0 && e[i] < 90.0, "lidar_beam_elevations_deg", e[i], "must lie in (-90, 90) degrees");
    require(i == 0 || e[i] > e[i - 1], "lidar_beam_elevations_deg", e[i],
            "must rise from the lowest beam to the highest");
  }
  require(camera == "kitti" || camera == "pinhole", "camera", camera, "is unknown (known: kitti, pinhole)");
  require(image_width_px >= 16 && image_width_px <= 8192, "image_width_px", image_width_px, "must be in 16..8192");
  require(image_height_px >= 16 && image_height_px <= 8192, "image_height_px", image_height_px, "must be in 16..8192");
  require(focal_px >= 1.0 && focal_px <= 100000.0, "focal_px", focal_px, "must be in 1..100000");
  require(principal_point_px.empty() || principal_point_px.size() == 2, "principal_point_px",
          std::to_string(principal_point_px.size()) + " numbers", "must be [cx, cy] or empty (the centre)");
  require(baseline_m > 0.0 && baseline_m <= 10.0, "baseline_m", baseline_m, "must be in (0, 10]");
}

namespace {
/// Shortest text that reads back to the same double, so a printed config reproduces a dataset.
std::string exact(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".en") == std::string::npos)
    text += ".0"; // keep it a real number for YAML
  return text;
}

std::string exactList(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i)
    text += (i ? ", " : "") + exact(values[i]);
  return text + "]";
}
} // namespace

void SyntheticConfig::print(std::ostream& out) const {
  out << "synthetic:\n"
      << "  scene: " << scene << "\n"
      << "  frames: " << frames << "\n"
      << "  seed: " << seed << "\n"
      << "  speed_mps: " << exact(speed_mps) << "\n"
      << "  frame_rate_hz: " << exact(frame_rate_hz) << "\n"
      << "  supersampling: " << supersampling << "\n"
      << "  image_noise_sigma: " << exact(image_noise_sigma) << "\n"
      << "  lidar_range_noise_m: " << exact(lidar_range_noise_m) << "\n"
      << "  lidar_dropout: " << exact(lidar_dropout) << "\n"
      << "  lidar_max_range_m: " << exact(lidar_max_range_m) << "\n"
      << "  lidar_min_range_m: " << exact(lidar_min_range_m) << "\n"
      << "  lidar_azimuth_step_deg: " << exact(lidar_azimuth_step_deg) << "\n"
      << "  lidar_upper_elevation_deg: " << exact(lidar_upper_elevation_deg) << "\n"
      << "  lidar_lower_elevation_deg: " << exact(lidar_lower_elevation_deg) << "\n"
      << "  lidar_model: " << lidar_model << "\n"
      << "  lidar_beam_elevations_deg: " << exactList(lidar_beam_elevations_deg) << "\n"
      << "  camera: " << camera << "\n"
      << "  image_width_px: " << image_width_px << "\n"
      << "  image_height_px: " << image_height_px << "\n"
      << "  focal_px: " << exact(focal_px) << "\n"
      << "  principal_point_px: " << exactList(principal_point_px) << "\n"
      << "  baseline_m: " << exact(baseline_m) << "\n"
      << "  textureless_share: " << exact(textureless_share) << "\n"
      << "  parked_car_share: " << exact(parked_car_share) << "\n"
      << "  mesh_max_edge_m: " << exact(mesh_max_edge_m) << "\n"
      << "  moving_cars_ahead: " << moving_cars_ahead << "\n"
      << "  moving_cars_oncoming: " << moving_cars_oncoming << "\n"
      << "  oncoming_car_speed_mps: " << exact(oncoming_car_speed_mps) << "\n"
      << "  oncoming_group_period_s: " << exact(oncoming_group_period_s) << "\n"
      << "  loop: " << (loop ? "true" : "false") << "\n";
  // Only when set: a dataset of exact poses, of one drive on its own street, is written as before.
  if (ins_poses)
    out << "  ins_poses: true\n"
        << "  ins_heading_drift_deg_per_s: " << exact(ins_heading_drift_deg_per_s) << "\n"
        << "  ins_position_error_m: " << exact(ins_position_error_m) << "\n";
  if (placed() || street_length_m != 0.0)
    out << "  start_m: " << exact(start_m) << "\n"
        << "  reverse: " << (reverse ? "true" : "false") << "\n"
        << "  street_length_m: " << exact(street_length_m) << "\n";
}

} // namespace msf::synthetic
