// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>

#include <opencv2/core/mat.hpp>

#include <string>
#include <utility>
#include <vector>

namespace msf {

/// Trajectories (T_world_cam0 per frame) from above, in the first one's first camera frame:
/// forward (z) to the right, left (-x) up, each axis fitted to the drive so that a lateral
/// drift of centimetres shows. msf_eval_odometry's picture and msf_reconstruct's report.
/// Throws InvalidInputError when there is no pose to draw.
cv::Mat plotTrajectoriesFromAbove(const std::vector<std::pair<std::string, PoseList>>& trajectories);

} // namespace msf
