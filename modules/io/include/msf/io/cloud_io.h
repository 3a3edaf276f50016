#pragma once
#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>

#include <string>

namespace msf {

/// Reads a .pcd or .ply file with whatever fields it has; throws IOError naming the file
/// when it is missing, unparsable or has no points.
void loadCloudBlob(const std::string& path, pcl::PCLPointCloud2& blob);

/// Loads a .pcd (or .ply) cloud; throws IOError naming the file when it is missing or
/// unreadable, and naming the field when the file lacks one that PointT needs (PCL itself
/// only warns and fills zeros). Organization (width x height) is kept.
template <typename PointT>
void loadCloud(const std::string& path, pcl::PointCloud<PointT>& cloud);

/// Saves a cloud by extension: .pcd as binary compressed (PCL tools' default), .ply binary.
/// Atomic: a temporary file then a rename; throws IOError naming the file or folder.
template <typename PointT>
void saveCloud(const std::string& path, const pcl::PointCloud<PointT>& cloud);

/// Saves a mesh by extension: .ply (binary), .obj or .vtk. Atomic.
void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh);

/// Loads a .ply/.obj/.vtk mesh; throws IOError naming the file.
void loadMesh(const std::string& path, pcl::PolygonMesh& mesh);

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/io/impl/cloud_io.hpp>
#endif
