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
PoseList streetTrajectory(const SyntheticConfig& config);

/// Frames driving out along the street: all of them, or the first leg of a loop.
int loopOutFrames(const SyntheticConfig& config);

/// Timestamps in seconds, frame i at i / frame_rate_hz.
std::vector<double> frameTimes(const SyntheticConfig& config);

} // namespace msf::synthetic
