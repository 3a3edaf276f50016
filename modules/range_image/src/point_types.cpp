// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The io templates (cloud files, organized conversion) for the interpolated-LiDAR point
// type, so tools and tests load and save it without including the implementations.
#include <msf/io/impl/cloud_io.hpp>
#include <msf/io/impl/organized_conversion.hpp>
#include <msf/range_image/point_types.h>

namespace msf {

template void loadCloud<PointXYZID>(const std::string&, pcl::PointCloud<PointXYZID>&);
template void fromCloudBlob<PointXYZID>(pcl::PCLPointCloud2, pcl::PointCloud<PointXYZID>&, const std::string&);
template void saveCloud<PointXYZID>(const std::string&, const pcl::PointCloud<PointXYZID>&);
template void depthImageToCloud<PointXYZID>(const cv::Mat&, const Calibration&, int, pcl::PointCloud<PointXYZID>&);
template cv::Mat cloudToDepthImage<PointXYZID>(const pcl::PointCloud<PointXYZID>&);

} // namespace msf
