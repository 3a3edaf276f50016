// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/scene.h>
#include <msf/synthetic/synthetic_config.h>

namespace msf::synthetic {

/// Adds the moving cars of `config` to a built street, as scene.movers (ids after the
/// static objects', materials after the static ones); the cameras drive along +z at
/// config.speed_mps from z = 0 at time 0.
///  - moving_cars_ahead cars drive ahead in the cameras' lane, one platoon 10..16 m apart
///    (centres) at one speed within 10 % of the cameras', the first starting 10..20 m ahead;
///    the speed is held to what keeps the first car 8..40 m ahead for the whole drive
///    (KITTI's van, followed all the way).
///  - Oncoming cars drive -z in the other lane at oncoming_car_speed_mps, in groups of
///    moving_cars_oncoming: the cameras meet a group's first car 0.35..0.45 s into every
///    oncoming_group_period_s, the next ones every 9..10.5 m of lane, so that in a short
///    sequence they pass early and the road they covered is seen empty afterwards.
/// Deterministic in config.seed, from counter-based streams of their own: the static
/// street does not change with these settings. For a placed drive (start_m, reverse) the cars
/// are laid out so along its own path and carried with it (driveTransform).
void addTraffic(const SyntheticConfig& config, Scene& scene);

} // namespace msf::synthetic
