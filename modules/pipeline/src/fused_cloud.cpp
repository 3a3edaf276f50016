// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/impl/organized_conversion.hpp> // depthImageToCloud for the fused point type
#include <msf/pipeline/fused_cloud.h>

namespace msf {

pcl::PointCloud<PointXYZRGBWeight> fusedCloud(const DepthFrame& fused, const Calibration& calibration) {
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
    }
  return cloud;
}

} // namespace msf
