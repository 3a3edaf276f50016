// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/impl/organized_conversion.hpp>

#include <pcl/point_types.h>

namespace msf {

namespace {
cv::Mat invertScaled(const cv::Mat& in, double numerator, const char* what) {
  if (in.type() != CV_32FC1)
    throw InvalidInputError(std::string(what) + " image must be CV_32FC1");
  cv::Mat out(in.size(), CV_32FC1);
  const float k = static_cast<float>(numerator);
  for (int v = 0; v < in.rows; ++v) {
    const float* i = in.ptr<float>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < in.cols; ++u)
      o[u] = (std::isfinite(i[u]) && i[u] > 0.f) ? k / i[u] : 0.f;
  }
  return out;
}
} // namespace

cv::Mat depthToDisparity(const cv::Mat& depth, const Calibration& calibration) {
  return depthToDisparity(depth, calibration.focalBaseline());
}

cv::Mat depthToDisparity(const cv::Mat& depth, double focal_baseline) {
  return invertScaled(depth, focal_baseline, "depth");
}

cv::Mat disparityToDepth(const cv::Mat& disparity, const Calibration& calibration) {
  return invertScaled(disparity, calibration.focalBaseline(), "disparity");
}

#define MSF_INSTANTIATE_ORGANIZED_CONVERSION(T)                                                        \
  template void depthImageToCloud<T>(const cv::Mat&, const Calibration&, int, pcl::PointCloud<T>&);   \
  template cv::Mat cloudToDepthImage<T>(const pcl::PointCloud<T>&);
MSF_INSTANTIATE_ORGANIZED_CONVERSION(pcl::PointXYZ)
MSF_INSTANTIATE_ORGANIZED_CONVERSION(pcl::PointXYZI)
MSF_INSTANTIATE_ORGANIZED_CONVERSION(pcl::PointXYZRGB)
MSF_INSTANTIATE_ORGANIZED_CONVERSION(pcl::PointXYZRGBA)

} // namespace msf
