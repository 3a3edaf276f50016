// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/lidar_simulator.h>
#include <msf/synthetic/synthetic_rig.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>

namespace msf::synthetic {

namespace {
constexpr double kPi = 3.14159265358979323846;

struct Sample {
  float x, y, z, intensity;
  bool valid;
};
} // namespace

LidarSimulator::LidarSimulator(const SyntheticConfig& config) : config_(config) {
  config_.validate();
  const std::vector<double> lowest_first = lidarBeamElevationsDeg(config_);
  elevations_deg_.assign(lowest_first.rbegin(), lowest_first.rend());
  steps_ = static_cast<int>(std::floor(360.0 / config_.lidar_azimuth_step_deg));
}

pcl::PointCloud<pcl::PointXYZI> LidarSimulator::scan(const SceneSnapshot& scene, const Eigen::Isometry3d& T_world_velo,
                                                     std::uint64_t frame_key) const {
  const int rings = ringCount(), steps = steps_;
  std::vector<Sample> samples(static_cast<std::size_t>(rings) * static_cast<std::size_t>(steps));
  const Eigen::Matrix3d R = T_world_velo.linear();
  const Eigen::Vector3d t = T_world_velo.translation();
  const V3 origin{static_cast<float>(t.x()), static_cast<float>(t.y()), static_cast<float>(t.z())};
  const double step_rad = 2.0 * kPi / steps;
  const auto seed = static_cast<std::uint64_t>(config_.seed);
  const float max_range = static_cast<float>(config_.lidar_max_range_m);
  const float min_range = static_cast<float>(config_.lidar_min_range_m);

  cv::parallel_for_(cv::Range(0, rings), [&](const cv::Range& ring_range) {
    for (int ring = ring_range.start; ring < ring_range.end; ++ring) {
      const double elevation = elevations_deg_[static_cast<std::size_t>(ring)] * kPi / 180.0;
      // hashKey(seed, frame_key, 0x11da7, ring, j) with the first four counters hashed once.
      const HashPrefix ring_key =
          HashPrefix(seed).then(frame_key).then(0x11da7ULL).then(static_cast<std::uint64_t>(ring));
      for (int j = 0; j < steps; ++j) {
        Sample& out =
            samples[static_cast<std::size_t>(ring) * static_cast<std::size_t>(steps) + static_cast<std::size_t>(j)];
        out.valid = false;
        const double azimuth = -kPi + (j + 0.5) * step_rad;
        const Eigen::Vector3d d_velo(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                     std::sin(elevation));
        const Eigen::Vector3d d_world = R * d_velo;
        const V3 dir{static_cast<float>(d_world.x()), static_cast<float>(d_world.y()), static_cast<float>(d_world.z())};
        const Ray ray{origin, dir};
        Hit hit;
        if (!scene.intersect(ray, 0.f, max_range, hit) || hit.t < min_range)
          continue;
        const auto key = ring_key.then(static_cast<std::uint64_t>(j)).value();
        const SurfaceResponse s = scene.shade(hit, ray.origin + ray.dir * hit.t, Footprint{});
        const double keep = (1.0 - config_.lidar_dropout) * (1.0 - 0.5 * s.glass);
        if (uniform01(mix64(key ^ 1)) >= keep)
          continue;
        const double range = hit.t + config_.lidar_range_noise_m * gaussian(mix64(key ^ 2));
        if (range <= 0.0)
          continue;
        const float incidence = std::fabs(dot(ray.dir, hit.normal));
        // KITTI's intensities depend little on incidence: the road at grazing angles still
        // returns ~0.3.
        const double intensity = s.reflectivity * (0.6 + 0.4 * incidence) + 0.02 * gaussian(mix64(key ^ 3));
        out.x = static_cast<float>(d_velo.x() * range);
        out.y = static_cast<float>(d_velo.y() * range);
        out.z = static_cast<float>(d_velo.z() * range);
        out.intensity = static_cast<float>(std::round(std::clamp(intensity, 0.0, 1.0) * 100.0) / 100.0);
        out.valid = true;
      }
    }
  });

  pcl::PointCloud<pcl::PointXYZI> cloud;
  cloud.reserve(samples.size());
  for (const Sample& s : samples) {
    if (!s.valid)
      continue;
    pcl::PointXYZI p;
    p.x = s.x;
    p.y = s.y;
    p.z = s.z;
    p.intensity = s.intensity;
    cloud.push_back(p);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  return cloud;
}

} // namespace msf::synthetic
