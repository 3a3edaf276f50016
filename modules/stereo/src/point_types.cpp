// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The io templates (cloud files, organized conversion) for the stereo point type, so tools
// and tests load and save it without including the implementations.
#include <msf/io/impl/cloud_io.hpp>
#include <msf/io/impl/organized_conversion.hpp>
#include <msf/stereo/point_types.h>

namespace msf {

template void loadCloud<PointXYZRGBConfidence>(const std::string&, pcl::PointCloud<PointXYZRGBConfidence>&);
template void fromCloudBlob<PointXYZRGBConfidence>(pcl::PCLPointCloud2, pcl::PointCloud<PointXYZRGBConfidence>&,
                                                   const std::string&);
template void saveCloud<PointXYZRGBConfidence>(const std::string&, const pcl::PointCloud<PointXYZRGBConfidence>&);
template void depthImageToCloud<PointXYZRGBConfidence>(const cv::Mat&, const Calibration&, int,
                                                       pcl::PointCloud<PointXYZRGBConfidence>&);
template cv::Mat cloudToDepthImage<PointXYZRGBConfidence>(const pcl::PointCloud<PointXYZRGBConfidence>&);

} // namespace msf
