// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>

#include <string>
#include <vector>

namespace msf {

/// Poses with their times, as the TUM RGB-D benchmark writes them: one line a pose,
/// "timestamp tx ty tz qx qy qz qw" (seconds, metres, a unit quaternion), T_world_cam0.
struct StampedPoses {
  std::vector<double> timestamps;
  PoseList poses;
};

/// Reads a TUM poses file; lines starting with '#' are comments. Throws IOError naming the
/// file and line for a line that is not 8 finite numbers or whose quaternion is not unit
/// (within 1e-3), or for times that do not rise.
StampedPoses loadTumPoses(const std::string& path);
/// Writes poses in TUM's format, atomically.
void saveTumPoses(const std::string& path, const StampedPoses& poses);
/// Whether a poses file's first pose line has TUM's 8 numbers (not KITTI's 12).
bool isTumPoses(const std::string& path);

} // namespace msf
