// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// Number of disparities for SGBM that covers a depth prior (the interpolated LiDAR depth,
/// CV_32F metres, 0 or NaN = none): the largest disparity f B / z of the prior minus
/// `min_disparity`, plus `margin_px`, rounded up to a multiple of 16 (OpenCV's requirement)
/// and clamped to [16, max_num_disparities]. SGBM's cost is linear in this number, and the
/// nearest LiDAR return on a KITTI street is some 5 m away (disparity < 70 of the usual 128),
/// so the prior roughly halves the matching time and uncovers the image's left band, where
/// SGBM has no result for the first num_disparities columns. A prior without valid pixels
/// gives max_num_disparities. Throws InvalidInputError for a wrong type, ConfigError for a
/// max_num_disparities that is not a positive multiple of 16.
int searchRangeFromDepth(const cv::Mat& depth, double focal_baseline, int min_disparity, int margin_px,
                         int max_num_disparities);

} // namespace msf
