// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/io/impl/pinhole_camera.hpp>
#include <msf/io/point_types.h> // the fields of the fused point type
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/point_types.h>

#include <opencv2/core/utility.hpp>
#include <pcl/type_traits.h>

#include <cmath>
#include <cstdint>
#include <string>

namespace msf {

namespace detail {

void requireOrganized(std::uint32_t width, std::uint32_t height, const std::string& what);

} // namespace detail

template <typename PointT>
DepthFrame toDepthFrame(const pcl::PointCloud<PointT>& cloud, const PinholeCamera* camera) {
  detail::requireOrganized(cloud.width, cloud.height, "cloud");
  DepthFrame frame;
  frame.camera = camera ? *camera : estimatePinholeCamera(cloud);
  const int rows = static_cast<int>(cloud.height), cols = static_cast<int>(cloud.width);
  frame.depth.create(rows, cols, CV_32FC1);
  constexpr bool kHasRgb = pcl::traits::has_field<PointT, pcl::fields::rgb>::value ||
                           pcl::traits::has_field<PointT, pcl::fields::rgba>::value;
  constexpr bool kHasWeight = pcl::traits::has_field<PointT, pcl::fields::weight>::value;
  constexpr bool kHasFreeSpaceWeight = pcl::traits::has_field<PointT, pcl::fields::free_space_weight>::value;
  if constexpr (kHasRgb)
    frame.color.create(rows, cols, CV_8UC3);
  if constexpr (kHasWeight)
    frame.weight.create(rows, cols, CV_32FC1);
  if constexpr (kHasFreeSpaceWeight)
    frame.free_space_weight.create(rows, cols, CV_32FC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const PointT* in = &cloud[static_cast<std::size_t>(v) * cols];
      float* depth = frame.depth.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        const PointT& p = in[u];
        depth[u] = (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.z > 0.f) ? p.z : 0.f;
        if constexpr (kHasRgb) {
          std::uint8_t* bgr = frame.color.ptr<std::uint8_t>(v) + 3 * u;
          bgr[0] = p.b;
          bgr[1] = p.g;
          bgr[2] = p.r;
        }
        if constexpr (kHasWeight) {
          using WeightT = typename pcl::traits::datatype<PointT, pcl::fields::weight>::type;
          const float w = static_cast<float>(*reinterpret_cast<const WeightT*>(
              reinterpret_cast<const std::uint8_t*>(&p) + pcl::traits::offset<PointT, pcl::fields::weight>::value));
          frame.weight.ptr<float>(v)[u] = std::isfinite(w) && w > 0.f ? w : 0.f;
        }
        if constexpr (kHasFreeSpaceWeight) {
          const float w = p.free_space_weight;
          frame.free_space_weight.ptr<float>(v)[u] = std::isfinite(w) && w > 0.f ? w : 0.f;
        }
      }
    }
  });
  frame.validate();
  return frame;
}

} // namespace msf
