// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <string>

namespace msf {

/// Reads a .pcd or .ply file with whatever fields it has; throws IOError naming the file
/// when it is missing, unparsable or has no points.
void loadCloudBlob(const std::string& path, pcl::PCLPointCloud2& blob);

/// Loads a .pcd (or .ply) cloud; throws IOError naming the file when it is missing or
/// unreadable, and naming the field when the file lacks one that PointT needs (PCL itself
/// only warns and fills zeros). A field of another numeric type than PointT's (an int32 or
/// float64 x) is converted, or refused when its values do not fit. Organization (width x
/// height) is kept.
template <typename PointT>
void loadCloud(const std::string& path, pcl::PointCloud<PointT>& cloud);

/// The second half of loadCloud, for a blob read by loadCloudBlob: checks that it has the
/// fields PointT needs, converts those of another numeric type (convertFieldTypes: PCL reads
/// an int32 or float64 x as 0) and fills `cloud`; `path` names the file in messages.
template <typename PointT>
void fromCloudBlob(pcl::PCLPointCloud2 blob, pcl::PointCloud<PointT>& cloud, const std::string& path);

/// Saves a cloud by extension: .pcd as binary compressed (PCL tools' default), .ply binary.
/// Atomic and checked to the end (msf/common/checked_write.h): throws IOError naming the
/// file or folder, and the system's reason for a failed write (a full disk), leaving no file.
template <typename PointT>
void saveCloud(const std::string& path, const pcl::PointCloud<PointT>& cloud);
/// The same for a cloud of any fields, with its sensor's pose (the .pcd's VIEWPOINT). A .pcd's
/// data must fit the 32-bit sizes of the binary compressed format (PCL's limit: 2/3 of 4 GiB),
/// which is checked before anything is written.
void saveCloudBlob(const std::string& path, const pcl::PCLPointCloud2& blob,
                   const Eigen::Vector4f& origin = Eigen::Vector4f::Zero(),
                   const Eigen::Quaternionf& orientation = Eigen::Quaternionf::Identity());

/// Throws IOError naming `path` unless it ends in a mesh's extension saveMesh writes: .ply, .obj
/// or .vtk (checked before a long run, not at its end).
void requireMeshExtension(const std::string& path);

/// Saves a mesh by extension: .ply (binary), .obj or .vtk. Atomic and checked to the end,
/// as saveCloud; a mesh without vertices is an InvalidInputError, and no file.
void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh);

/// Loads a .ply/.obj/.vtk mesh; throws IOError naming the file.
void loadMesh(const std::string& path, pcl::PolygonMesh& mesh);

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/io/impl/cloud_io.hpp>
#endif
