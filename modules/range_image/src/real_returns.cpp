// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/range_image/real_returns.h>

#include <string>

namespace msf {

cv::Mat realReturns(const cv::Mat& depth, const cv::Mat& distance) {
  if (depth.type() != CV_32FC1 || distance.type() != CV_32FC1)
    throw InvalidInputError("realReturns: the depth and distance images must be CV_32FC1");
  if (depth.size() != distance.size())
    throw InvalidInputError("realReturns: the depth image is " + std::to_string(depth.cols) + "x" +
                            std::to_string(depth.rows) + " but the distance image is " +
                            std::to_string(distance.cols) + "x" + std::to_string(distance.rows));
  cv::Mat sparse(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    const float* d = distance.ptr<float>(v);
    float* out = sparse.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      out[u] = d[u] == 0.f && z[u] > 0.f ? z[u] : 0.f;
  }
  return sparse;
}

} // namespace msf
