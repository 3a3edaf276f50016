// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

namespace msf {

/// Relative depth difference above which a LiDAR return and the stereo depth at its pixel
/// disagree: far beyond SGBM's error at the depths where both measure.
constexpr double kDisagreementRelative = 0.1;
/// A run's median share of disagreeing pixels above which the rig is probably wrong: well above
/// what right rigs give, KITTI's and small ones', and below an extrinsic given inverted
/// (docs/results.md, "A rig checked by its two sensors").
constexpr double kRigDisagreementWarning = 0.3;

/// Of the pixels with a real LiDAR return (`lidar_distance` 0, `lidar_depth` > 0) and a stereo
/// depth, the share where the two differ by more than kDisagreementRelative; NaN where no pixel
/// has both. A wrong extrinsic, baseline or unit shows as a large share.
double lidarStereoDisagreement(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance,
                               const cv::Mat& stereo_depth);

/// The median of the frames' disagreements `shares`, NaN skipped; NaN when none is a number.
double medianDisagreement(const std::vector<double>& shares);

/// The warning for a run whose frames' median disagreement is above kRigDisagreementWarning,
/// naming what to check; "" otherwise.
std::string rigDisagreementWarning(const std::vector<double>& shares);

} // namespace msf
