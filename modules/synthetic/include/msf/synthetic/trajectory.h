// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>
#include <msf/synthetic/synthetic_config.h>

#include <vector>

namespace msf::synthetic {

/// T_world_cam0 of every frame: constant speed along the street (world z), a gentle lateral
/// sway (0.4 m over 150 m) with the heading following the path, camera height constant.
/// Frame 0 is the identity, so the world is camera 0's frame at frame 0, as in KITTI.
/// With config.loop: (frames - kLoopTurnFrames) / 2 frames out, a half-circle turn to the
/// other lane, and back along it at the same speed (the second half sees the first's street).
/// A placed drive (start_m, reverse) is that path carried by driveTransform: its poses are in
/// the street's world, where other drives of the street meet it.
PoseList streetTrajectory(const SyntheticConfig& config);

/// Where a drive of config.start_m and config.reverse lies in the street's world: the identity
/// for one from the start heading +z; start_m metres along z; reversed, turned round about the
/// road's axis there, so that it heads -z in the other lane. The drive's own path and its
/// traffic are laid out from the start and carried by it.
Eigen::Isometry3d driveTransform(const SyntheticConfig& config);

/// Frames driving out along the street: all of them, or the first leg of a loop.
int loopOutFrames(const SyntheticConfig& config);

/// Timestamps in seconds, frame i at i / frame_rate_hz.
std::vector<double> frameTimes(const SyntheticConfig& config);

} // namespace msf::synthetic
