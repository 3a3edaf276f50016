// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/io/compressed_pcd.h>
#include <msf/io/field_conversion.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <cstdint>
#include <string>

namespace msf {

template <typename PointT>
void loadCloud(const std::string& path, pcl::PointCloud<PointT>& cloud) {
  pcl::PCLPointCloud2 blob;
  loadCloudBlob(path, blob);
  fromCloudBlob(std::move(blob), cloud, path);
}

template <typename PointT>
void fromCloudBlob(pcl::PCLPointCloud2 blob, pcl::PointCloud<PointT>& cloud, const std::string& path) {
  std::vector<pcl::PCLPointField> wanted;
  pcl::for_each_type<typename pcl::traits::fieldList<PointT>::type>(pcl::detail::FieldAdder<PointT>(wanted));
  requireFields(blob, wanted, path);
  if (static_cast<std::uint64_t>(blob.width) * blob.height == 0) {
    // PCL's conversion indexes each row's first point, which an empty cloud of rows has not.
    cloud.clear();
    cloud.header = blob.header;
    return;
  }
  convertFieldTypes(blob, wanted, path);
  pcl::fromPCLPointCloud2(blob, cloud);
}

namespace detail {
/// saveCloudBlob with the points in `data` (`bytes` of them), laid out as `layout` says.
void saveCloudData(const std::string& path, const pcl::PCLPointCloud2& layout, const std::uint8_t* data,
                   std::size_t bytes, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation);
} // namespace detail

template <typename PointT>
void saveCloud(const std::string& path, const pcl::PointCloud<PointT>& cloud) {
  if (cloud.empty())
    throw InvalidInputError("cannot write '" + path + "': the cloud is empty");
  // The points are read where they lie, not copied into a PCLPointCloud2.
  detail::saveCloudData(path, pointLayout(cloud), reinterpret_cast<const std::uint8_t*>(cloud.data()),
                        cloud.size() * sizeof(PointT), cloud.sensor_origin_, cloud.sensor_orientation_);
}

} // namespace msf
