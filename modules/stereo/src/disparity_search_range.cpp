// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/stereo/disparity_search_range.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

int searchRangeFromDepth(const cv::Mat& depth, double focal_baseline, int min_disparity, int margin_px,
                         int max_num_disparities) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("depth prior must be CV_32FC1 (metres)");
  if (max_num_disparities <= 0 || max_num_disparities % 16 != 0)
    throw ConfigError("the largest number of disparities must be a positive multiple of 16, not " +
                      std::to_string(max_num_disparities));
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("depth prior: focal length x baseline must be > 0");
  float nearest = std::numeric_limits<float>::infinity();
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      if (z[u] > 0.f && z[u] < nearest)
        nearest = z[u];
  }
  if (!std::isfinite(nearest))
    return max_num_disparities;
  const double needed = focal_baseline / nearest - min_disparity + margin_px;
  const int rounded = static_cast<int>(std::ceil(needed / 16.0)) * 16;
  return std::clamp(rounded, 16, max_num_disparities);
}

} // namespace msf
