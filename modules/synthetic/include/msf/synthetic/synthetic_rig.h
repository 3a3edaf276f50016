// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/synthetic/synthetic_config.h>

#include <vector>

namespace msf::synthetic {

/// The rig msf_synth renders, from the `synthetic` section: KITTI's cameras (kittiRig) or a
/// pinhole grey pair (camera: pinhole; the colour camera is the grey left one), with the
/// LiDAR mounted as KITTI's (0.08 m above and 0.27 m behind camera 0) and its beams in
/// `lidar` (rings, elevations; not sweeping: the simulated scan is a snapshot).
Calibration syntheticRig(const SyntheticConfig& config);

/// The LiDAR's beam elevations in degrees, lowest first: KITTI's HDL-64E (two blocks of 32,
/// the upper 1/3 degree apart down from lidar_upper_elevation_deg, the lower evenly down to
/// lidar_lower_elevation_deg), a Velodyne HDL-32E (-30.67..+10.67, 4/3 degree apart), or
/// lidar_beam_elevations_deg.
std::vector<double> lidarBeamElevationsDeg(const SyntheticConfig& config);

/// Sets the camera and LiDAR keys of `config` from a rig (msf_synth -rig FILE): a pinhole
/// pair of its image size, focal length, principal point and baseline, and its beams when it
/// lists them. Throws InvalidInputError naming what a synthetic rig cannot be (fx != fy, rings
/// without elevations, no LiDAR).
void applyRig(const Calibration& rig, SyntheticConfig& config);

} // namespace msf::synthetic
