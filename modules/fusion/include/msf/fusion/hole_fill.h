// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// Fills the small holes of a fused depth image (fusion.hole_fill_px): a pixel without depth
/// (not > 0) that has a depth within `radius_px` pixels along its row, or else along its column,
/// takes the nearer one's (of two at the same distance, the nearer surface's). So a dark car the
/// LiDAR lost, or a stereo hole between rings, is not a hole in the depth a user gets. A filled
/// pixel is a guess: its `weight` and `free_weight` (those not empty) become 0, and the map does
/// not integrate it. Pixels of `excluded` (CV_8UC1, non-zero; empty = none: the open sky) stay
/// empty, and depth does not carry across them. Returns the filled pixels (CV_8UC1, 255).
/// Throws InvalidInputError, changing nothing, when an image is not CV_32FC1 (the mask CV_8UC1)
/// of the depth's size.
cv::Mat fillSmallHoles(cv::Mat& depth, cv::Mat& weight, cv::Mat& free_weight, const cv::Mat& excluded, int radius_px);

} // namespace msf
