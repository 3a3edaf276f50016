// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/io/organized_conversion.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>

namespace msf {

template <typename PointT>
void depthImageToCloud(const cv::Mat& depth, const Calibration& calibration, int camera,
                       pcl::PointCloud<PointT>& cloud) {
  if (depth.type() != CV_32FC1)
    throw InvalidInputError("depth image must be CV_32FC1 (metres)");
  if (calibration.image_size.width > 0 && depth.size() != calibration.image_size)
    throw InvalidInputError("depth image is " + std::to_string(depth.cols) + "x" + std::to_string(depth.rows) +
                            " but calibration '" + calibration.source + "' is " +
                            std::to_string(calibration.image_size.width) + "x" +
                            std::to_string(calibration.image_size.height));
  const float fx = static_cast<float>(calibration.fx(camera)), fy = static_cast<float>(calibration.fy(camera));
  const float cx = static_cast<float>(calibration.cx(camera)), cy = static_cast<float>(calibration.cy(camera));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cloud.resize(static_cast<std::size_t>(depth.cols) * depth.rows);
  cloud.width = static_cast<std::uint32_t>(depth.cols);
  cloud.height = static_cast<std::uint32_t>(depth.rows);
  cloud.header.frame_id = cameraFrameId(camera);
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& range) {
    bool all = true;
    for (int v = range.start; v < range.end; ++v) {
      const float* row = depth.ptr<float>(v);
      PointT* out = &cloud[static_cast<std::size_t>(v) * depth.cols];
      for (int u = 0; u < depth.cols; ++u) {
        const float z = row[u];
        PointT& p = out[u];
        if (std::isfinite(z) && z > 0.f) {
          p.x = (static_cast<float>(u) - cx) * z / fx;
          p.y = (static_cast<float>(v) - cy) * z / fy;
          p.z = z;
        } else {
          p.x = p.y = p.z = nan;
          all = false;
        }
      }
    }
    if (!all)
      dense = false;
  });
  cloud.is_dense = dense;
}

template <typename PointT>
cv::Mat cloudToDepthImage(const pcl::PointCloud<PointT>& cloud) {
  if (!cloud.isOrganized() || cloud.empty())
    throw InvalidInputError("expected an organized cloud (height > 1), got " + std::to_string(cloud.width) + "x" +
                            std::to_string(cloud.height));
  cv::Mat depth(static_cast<int>(cloud.height), static_cast<int>(cloud.width), CV_32FC1);
  parallelFor(cv::Range(0, depth.rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      float* row = depth.ptr<float>(v);
      const PointT* in = &cloud[static_cast<std::size_t>(v) * cloud.width];
      for (int u = 0; u < depth.cols; ++u)
        row[u] = (std::isfinite(in[u].z) && in[u].z > 0.f) ? in[u].z : 0.f;
    }
  });
  return depth;
}

} // namespace msf
