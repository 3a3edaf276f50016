// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/car.h>
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/traffic.h>
#include <msf/synthetic/trajectory.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace msf::synthetic {

namespace {

// Keys of the movers' streams, apart from the static street's.
constexpr std::uint64_t kAheadStream = 0xa4eadULL;
constexpr std::uint64_t kOncomingStream = 0x0c0a1ULL;
constexpr float kPiF = 3.14159265f;
constexpr double kMinGapAheadM = 8.0, kMaxGapAheadM = 40.0;
// Centre spacing of consecutive oncoming cars: 4.2 m between bumpers at the least.
constexpr double kMinSpacingOncomingM = 9.0, kMaxSpacingOncomingM = 10.5;

/// Car `id` with its look, tyres and a small offset from the lane's centre drawn from
/// `rng`, its centre at `z` at time 0.
void addCar(SequentialRng& rng, Scene& scene, std::uint32_t id, float lane_x, double z, float yaw, double speed_mps) {
  const CarLook look = drawCarLook(rng, scene);
  const std::uint16_t tyre = scene.addMaterial({MaterialType::Tyre, 0.035f, 0.035f, 0.035f, rng.seed32(), 0.08f});
  const float x = lane_x + static_cast<float>(rng.uniform(-0.15, 0.15));
  scene.movers.emplace_back(id, carSolids(look, tyre, id), V3{x, scene.layout.ground_y, static_cast<float>(z)}, yaw,
                            static_cast<float>(speed_mps));
}

/// The movers from `first` on, laid out along a drive from the street's start, carried to the
/// drive's place `T_world_drive` (a turn about y adds to their heading).
void carryToDrive(const Eigen::Isometry3d& T_world_drive, std::vector<MovingObject>& movers, std::size_t first) {
  const Eigen::Matrix3d R = T_world_drive.linear();
  const float turn = static_cast<float>(std::atan2(R(0, 2), R(2, 2)));
  for (std::size_t i = first; i < movers.size(); ++i) {
    const MovingObject& m = movers[i];
    const V3 s = m.originAt(0.0);
    const Eigen::Vector3d start = T_world_drive * Eigen::Vector3d(s.x, s.y, s.z);
    movers[i] = MovingObject(m.object(), m.solids(),
                             {static_cast<float>(start.x()), static_cast<float>(start.y()), static_cast<float>(start.z())},
                             m.yaw() + turn, m.speedMps());
  }
}

/// The cars of a drive from the street's start, heading +z in the right-hand lane.
void addTrafficAlongDrive(const SyntheticConfig& config, Scene& scene) {
  const auto seed = static_cast<std::uint64_t>(config.seed);
  const double v = config.speed_mps;
  // The cameras drive along the street (z = v t) for the drive, or a loop's first leg: the
  // cars are met there. A loop's turn meets none (no group within 3 s before it); on the way
  // back the cameras follow the oncoming cars met before, at their speed.
  const double duration = (loopOutFrames(config) - 1) / config.frame_rate_hz;
  const double last_meeting_s = config.loop ? duration - 3.0 : 1e300;
  std::uint32_t id = scene.objectCount();

  if (config.moving_cars_ahead > 0) {
    SequentialRng lane(hashKey(seed, kAheadStream));
    double z = lane.uniform(10.0, 20.0);
    double speed = v * lane.uniform(0.9, 1.1);
    if (duration > 0.0)
      speed = std::clamp(speed, v - (z - kMinGapAheadM) / duration, v + (kMaxGapAheadM - z) / duration);
    for (int j = 0; j < config.moving_cars_ahead; ++j) {
      SequentialRng rng(hashKey(seed, kAheadStream, static_cast<std::uint64_t>(j) + 1));
      if (j > 0)
        z += rng.uniform(10.0, 16.0);
      addCar(rng, scene, ++id, scene.layout.rightLaneX(), z, 0.f, speed);
    }
  }

  if (config.moving_cars_oncoming > 0) {
    const double u = config.oncoming_car_speed_mps, closing = v + u;
    const double period = config.oncoming_group_period_s;
    const int groups = static_cast<int>(std::floor(duration / period)) + 1;
    double last_meeting = -1e9;
    for (int g = 0; g < groups; ++g) {
      SequentialRng group(hashKey(seed, kOncomingStream, static_cast<std::uint64_t>(g) + 1));
      double meeting = g * period + group.uniform(0.35, 0.45);
      for (int j = 0; j < config.moving_cars_oncoming; ++j) {
        SequentialRng rng(
            hashKey(seed, kOncomingStream, static_cast<std::uint64_t>(g) + 1, static_cast<std::uint64_t>(j) + 1));
        if (j > 0)
          meeting += rng.uniform(kMinSpacingOncomingM, kMaxSpacingOncomingM) / closing;
        // A long group runs into the next one's time: keep the spacing.
        meeting = std::max(meeting, last_meeting + kMinSpacingOncomingM / closing);
        last_meeting = meeting;
        if (meeting > last_meeting_s)
          break;
        // Its centre passes the cameras (at z = v t) at `meeting`, driving -z at u.
        addCar(rng, scene, ++id, scene.layout.leftLaneX(), (v + u) * meeting, kPiF, u);
      }
    }
  }
}

} // namespace

void addTraffic(const SyntheticConfig& config, Scene& scene) {
  const std::size_t first = scene.movers.size();
  addTrafficAlongDrive(config, scene);
  if (config.placed())
    carryToDrive(driveTransform(config), scene.movers, first);
}

} // namespace msf::synthetic
