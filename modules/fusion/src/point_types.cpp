// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The io templates (cloud files, organized conversion) for the fused point type, so tools
// and tests load and save it without including the implementations.
#include <msf/fusion/point_types.h>
#include <msf/io/impl/cloud_io.hpp>
#include <msf/io/impl/organized_conversion.hpp>

namespace msf {

template void loadCloud<PointXYZRGBWeight>(const std::string&, pcl::PointCloud<PointXYZRGBWeight>&);
template void fromCloudBlob<PointXYZRGBWeight>(pcl::PCLPointCloud2, pcl::PointCloud<PointXYZRGBWeight>&, const std::string&);
template void saveCloud<PointXYZRGBWeight>(const std::string&, const pcl::PointCloud<PointXYZRGBWeight>&);
template void depthImageToCloud<PointXYZRGBWeight>(const cv::Mat&, const Calibration&, int,
                                                   pcl::PointCloud<PointXYZRGBWeight>&);
template cv::Mat cloudToDepthImage<PointXYZRGBWeight>(const pcl::PointCloud<PointXYZRGBWeight>&);

} // namespace msf
