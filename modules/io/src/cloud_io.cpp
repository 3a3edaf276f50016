#include <msf/io/impl/cloud_io.hpp>

#include <pcl/io/obj_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

namespace msf {

namespace detail {
void readCloudBlob(const std::string& path, pcl::PCLPointCloud2& blob) {
  requireFile(path, "cloud");
  const std::string ext = fileExtension(path);
  int result = -1;
  if (ext == ".pcd")
    result = pcl::PCDReader().read(path, blob);
  else if (ext == ".ply")
    result = pcl::PLYReader().read(path, blob);
  else
    throw IOError("cloud '" + path + "' is neither .pcd nor .ply");
  if (result < 0)
    throw IOError("cloud '" + path + "' cannot be parsed as " + ext.substr(1));
}
} // namespace detail

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh) {
  const std::string ext = fileExtension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".vtk")
    throw IOError("cannot write mesh '" + path + "': use .ply, .obj or .vtk");
  writeAtomically(path, [&](const std::string& tmp) {
    int result = -1;
    if (ext == ".ply")
      result = pcl::io::savePLYFileBinary(tmp, mesh);
    else if (ext == ".obj")
      result = pcl::io::saveOBJFile(tmp, mesh);
    else
      result = pcl::io::saveVTKFile(tmp, mesh);
    if (result != 0)
      throw IOError("cannot write mesh '" + path + "'");
  });
}

void loadMesh(const std::string& path, pcl::PolygonMesh& mesh) {
  requireFile(path, "mesh");
  const std::string ext = fileExtension(path);
  int result = -1;
  if (ext == ".ply")
    result = pcl::io::loadPLYFile(path, mesh);
  else if (ext == ".obj")
    result = pcl::io::loadOBJFile(path, mesh);
  else if (ext == ".vtk")
    result = pcl::io::loadPolygonFileVTK(path, mesh);
  else
    throw IOError("mesh '" + path + "' is not .ply, .obj or .vtk");
  if (result < 0)
    throw IOError("mesh '" + path + "' cannot be parsed");
}

#define MSF_INSTANTIATE_CLOUD_IO(T)                                                \
  template void loadCloud<T>(const std::string&, pcl::PointCloud<T>&);            \
  template void saveCloud<T>(const std::string&, const pcl::PointCloud<T>&);
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZ)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZI)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGB)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGBA)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointNormal)

} // namespace msf
