// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// Exact Euclidean distance, in pixels, from every pixel to the nearest sample (a pixel of
/// `depth` > 0): distances along the rows, then for each pixel the nearest of them over the
/// rows outwards until no farther row can be nearer. On a LiDAR scan's projection (samples
/// on rows a few pixels apart) that search is a few rows deep and vectorised across columns.
/// `distance` is CV_32FC1 (0 on a sample, +inf everywhere when there is none). When
/// `nearest` is given it receives, as CV_32SC1, the row-major index of a nearest sample
/// (-1 when there is none). At most `threads` threads of OpenCV's pool run it (0: all of
/// them); the result does not depend on their number. Images up to 8192 px on a side (InvalidInputError beyond).
void distanceToSamples(const cv::Mat& depth, cv::Mat& distance, cv::Mat* nearest = nullptr, int threads = 0);

} // namespace msf
