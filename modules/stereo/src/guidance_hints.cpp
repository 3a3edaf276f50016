// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/stereo/guidance_hints.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace msf {

cv::Mat guidanceHints(const cv::Mat& sparse_depth, double focal_baseline, int bridge_rows, float bridge_agreement) {
  if (sparse_depth.type() != CV_32FC1)
    throw InvalidInputError("guidance hints: the sparse depth must be CV_32FC1 (metres)");
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("guidance hints: focal length x baseline must be > 0");
  if (bridge_rows < 0 || !(bridge_agreement >= 0.f))
    throw InvalidInputError("guidance hints: bridge rows and agreement must be >= 0");
  cv::Mat hints(sparse_depth.size(), CV_16SC1);
  const double scale = 16.0 * focal_baseline;
  const int cols = sparse_depth.cols;
  // Per column, the row and hint of the last return above the current row.
  std::vector<int> last_row(static_cast<std::size_t>(cols), -1), last_hint(static_cast<std::size_t>(cols), 0);
  for (int v = 0; v < sparse_depth.rows; ++v) {
    const float* z = sparse_depth.ptr<float>(v);
    std::int16_t* h = hints.ptr<std::int16_t>(v);
    for (int u = 0; u < cols; ++u) {
      if (!(z[u] > 0.f) || !std::isfinite(z[u])) {
        h[u] = 0;
        continue;
      }
      const int hint = static_cast<int>(std::clamp(std::lround(scale / z[u]), 1L, 32767L));
      h[u] = static_cast<std::int16_t>(hint);
      const int above = last_row[static_cast<std::size_t>(u)], above_hint = last_hint[static_cast<std::size_t>(u)];
      if (above >= 0 && v - above > 1 && v - above <= bridge_rows &&
          static_cast<float>(std::abs(hint - above_hint)) <= bridge_agreement * static_cast<float>(std::max(hint, above_hint))) {
        const int span = v - above;
        for (int r = above + 1; r < v; ++r) // linear in the row, rounded
          hints.at<std::int16_t>(r, u) = static_cast<std::int16_t>(
              (above_hint * (v - r) + hint * (r - above) + span / 2) / span);
      }
      last_row[static_cast<std::size_t>(u)] = v;
      last_hint[static_cast<std::size_t>(u)] = hint;
    }
  }
  return hints;
}

cv::Mat rightViewHintsMirrored(const cv::Mat& hints) {
  if (hints.type() != CV_16SC1)
    throw InvalidInputError("guidance hints: the hints must be CV_16SC1 (disparity x 16)");
  cv::Mat right = cv::Mat::zeros(hints.size(), CV_16SC1);
  for (int v = 0; v < hints.rows; ++v) {
    const std::int16_t* h = hints.ptr<std::int16_t>(v);
    std::int16_t* r = right.ptr<std::int16_t>(v);
    for (int u = 0; u < hints.cols; ++u) {
      const int ur = u - (h[u] + 8) / 16;
      if (h[u] > 0 && ur >= 0)
        r[ur] = std::max(r[ur], h[u]);
    }
  }
  cv::flip(right, right, 1);
  return right;
}

} // namespace msf
