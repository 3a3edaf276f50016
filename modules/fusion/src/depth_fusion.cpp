// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/fusion/impl/depth_fusion.hpp>

#include <pcl/point_types.h>

namespace msf {

template class DepthFusion<PointXYZID, PointXYZRGBConfidence, PointXYZRGBWeight>;
template class DepthFusion<PointXYZID, PointXYZRGBConfidence, pcl::PointXYZRGB>;
template class DepthFusion<pcl::PointXYZ, pcl::PointXYZ, pcl::PointXYZ>;
template class DepthFusion<pcl::PointXYZI, pcl::PointXYZRGB, pcl::PointXYZRGB>;

} // namespace msf
