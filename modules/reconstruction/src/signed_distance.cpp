// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/reconstruction/signed_distance.h>

namespace msf {

void ProjectiveDistance::pixelScales(const cv::Mat& depth, const PinholeCamera&, cv::Mat& scale,
                                     cv::Mat& extent) const {
  scale.create(depth.size(), CV_32FC1);
  scale.setTo(1.f);
  extent.create(depth.size(), CV_32FC1);
  extent.setTo(0.f);
}

void PlaneDistance::pixelScales(const cv::Mat& depth, const PinholeCamera& camera, cv::Mat& scale,
                                cv::Mat& extent) const {
  planeDistanceScale(depth, camera, config_, scale);
  smoothSurfaceExtent(depth, config_.max_curvature, extent);
}

} // namespace msf
