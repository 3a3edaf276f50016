// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// False-colour picture of a depth image (CV_32F metres, 0/NaN = none) for people: near is
/// warm, far is cold (OpenCV's turbo map, inverted), pixels without depth are black.
/// `min_m`/`max_m` <= 0 pick the 2nd and 98th percentiles of the valid depths.
/// With `legend`, a colour bar labelled in metres is appended below the image.
cv::Mat colorizeDepth(const cv::Mat& depth, float min_m = 0.f, float max_m = 0.f, bool legend = true);

} // namespace msf
