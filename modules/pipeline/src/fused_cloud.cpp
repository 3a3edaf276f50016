// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/impl/organized_conversion.hpp> // depthImageToCloud for the fused point type
#include <msf/pipeline/fused_cloud.h>

#include <limits>

namespace msf {

pcl::PointCloud<PointXYZRGBWeight> fusedCloud(const FrameResult& result, const Calibration& calibration) {
  const DepthFrame& fused = result.fused;
  const cv::Mat& free_weight = fused.free_space_weight.empty() ? fused.weight : fused.free_space_weight;
  const bool has_sky = result.sky_depth.size() == fused.depth.size();
  pcl::PointCloud<PointXYZRGBWeight> cloud;
  depthImageToCloud(fused.depth, calibration, 0, cloud);
  for (int v = 0; v < fused.depth.rows; ++v)
    for (int u = 0; u < fused.depth.cols; ++u) {
      PointXYZRGBWeight& p = cloud.at(u, v);
      const cv::Vec3b bgr = fused.color.at<cv::Vec3b>(v, u);
      p.b = bgr[0];
      p.g = bgr[1];
      p.r = bgr[2];
      p.a = 255;
      p.weight = fused.weight.at<float>(v, u);
      p.free_space_weight = free_weight.at<float>(v, u);
      p.sky_depth = has_sky ? result.sky_depth.at<float>(v, u) : std::numeric_limits<float>::quiet_NaN();
    }
  return cloud;
}

} // namespace msf
