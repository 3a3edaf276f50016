// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>

namespace msf {

/// Depth image (CV_32F metres, 0 or NaN = none) to an organized cloud of the same size in
/// the rectified frame of `camera`: x = (u - cx) z / fx, y = (v - cy) z / fy. Pixels without
/// depth become NaN points and the cloud is not dense. Other fields are left as PointT's
/// default. Throws InvalidInputError if the image is not CV_32FC1 or, when the calibration
/// knows its image size, the sizes differ.
template <typename PointT>
void depthImageToCloud(const cv::Mat& depth, const Calibration& calibration, int camera,
                       pcl::PointCloud<PointT>& cloud);

/// Organized cloud to a depth image (CV_32F, z in metres, 0 = none).
/// Throws InvalidInputError naming the problem when the cloud is not organized.
template <typename PointT>
cv::Mat cloudToDepthImage(const pcl::PointCloud<PointT>& cloud);

/// Disparity (pixels, grey pair) from depth and back: d = f B / z; 0 stays 0.
cv::Mat depthToDisparity(const cv::Mat& depth, const Calibration& calibration);
/// The same with f B given (pixels x metres).
cv::Mat depthToDisparity(const cv::Mat& depth, double focal_baseline);
cv::Mat disparityToDepth(const cv::Mat& disparity, const Calibration& calibration);

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/io/impl/organized_conversion.hpp>
#endif
