// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/scene.h>
#include <msf/synthetic/synthetic_config.h>

namespace msf::synthetic {

/// Builds the street for a camera that drives from world z = 0 to z = `path_end_z`: asphalt
/// with lane markings, kerbs and sidewalks, façades with windows (brick or plaster) and
/// textureless blank walls, parked cars, street lamps, signs, trees and pedestrians, closed
/// by cross buildings beyond the LiDAR's range at both ends, and the moving cars of
/// addTraffic (traffic.h). Cars, poles (lamps, signs) and people are foreground objects
/// with instance ids. Deterministic in config.seed.
Scene buildStreetScene(const SyntheticConfig& config, double path_end_z);

} // namespace msf::synthetic
