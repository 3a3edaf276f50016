// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

namespace msf {

/// Writes `blob` to `out` as a binary_compressed .pcd, as PCL's PCDWriter::writeBinaryCompressed
/// does (its header, each field's values side by side, compressed by pcl::lzfCompress), with
/// `comment` (whole "# ..." lines, each ending in a newline) after the first line, where PCD
/// readers skip it. A body up to 1 MiB is byte for byte PCL's; a larger one is compressed in
/// pieces of 1 MiB on every core, one LZF stream that PCL reads as its own (the same bytes on
/// any number of threads), and a comment line says where the pieces lie (readCompressedPieces).
/// PCL's stream writer hands the compressed body to the stream a character at a time, which
/// dominates the writing of a large cloud; here it is one write.
/// Throws IOError when the points are more than the format's 32-bit sizes hold or do not
/// compress.
void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin,
                        const Eigen::Quaternionf& orientation, const std::string& comment = "");

/// The values of one field of a run of points, one after another into `out`: `field` counts
/// the layout's fields but padding ("_"), `first` and `count` the points. Called for the body's
/// pieces on every core at once: it must only read what it shares.
using FieldValues = std::function<void(std::size_t field, std::size_t first, std::size_t count, char* out)>;

/// The same with the points' values given field by field by `values`, for points that lie
/// nowhere whole (a volume's voxels in its blocks); `layout`'s data is not read.
void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& layout, const FieldValues& values,
                        const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                        const std::string& comment = "");

/// The same with the points in `data` (`bytes` of them), laid out as `layout` says; its own
/// data is not read.
void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& layout, const std::uint8_t* data,
                        std::size_t bytes, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                        const std::string& comment = "");

/// Reads the body of a binary_compressed .pcd that writeCompressedPcd wrote in pieces into
/// `blob`, which holds the file's fields and size (pcl::PCDReader::readHeader), as
/// PCDReader::read does (the points, is_dense), the pieces unpacked on every core: the header
/// line the writer adds says where each begins. False, with `blob` as it was, for any other
/// file, or one whose pieces do not make up its body: PCL's reader reads it whole.
bool readCompressedPieces(const std::string& path, std::size_t data_index, pcl::PCLPointCloud2& blob);

/// What a PCLPointCloud2 of `width` x `height` points of PointT holds but its points: the fields and the size.
template <typename PointT>
pcl::PCLPointCloud2 pointLayout(std::uint32_t width, std::uint32_t height, bool is_dense) {
  pcl::PCLPointCloud2 layout;
  pcl::toPCLPointCloud2(pcl::PointCloud<PointT>(), layout); // the fields
  layout.width = width;
  layout.height = height;
  layout.point_step = sizeof(PointT);
  layout.row_step = layout.point_step * layout.width;
  layout.is_dense = is_dense;
  return layout;
}

/// The same for `cloud`'s points.
template <typename PointT>
pcl::PCLPointCloud2 pointLayout(const pcl::PointCloud<PointT>& cloud) {
  const bool unsized = cloud.width == 0 && cloud.height == 0; // as pcl::toPCLPointCloud2 takes it
  return pointLayout<PointT>(unsized ? static_cast<std::uint32_t>(cloud.size()) : cloud.width,
                             unsized ? 1 : cloud.height, cloud.is_dense);
}

/// The same for a cloud, read where it lies (no copy into a PCLPointCloud2).
template <typename PointT>
void writeCompressedPcd(std::ostream& out, const pcl::PointCloud<PointT>& cloud, const std::string& comment = "") {
  writeCompressedPcd(out, pointLayout(cloud), reinterpret_cast<const std::uint8_t*>(cloud.data()),
                     cloud.size() * sizeof(PointT), cloud.sensor_origin_, cloud.sensor_orientation_, comment);
}

} // namespace msf
