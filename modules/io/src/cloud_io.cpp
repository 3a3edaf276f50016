#include <msf/io/impl/cloud_io.hpp>

#include <pcl/io/obj_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

namespace msf {

void loadCloudBlob(const std::string& path, pcl::PCLPointCloud2& blob) {
  requireFile(path, "cloud");
  const std::string ext = fileExtension(path);
  int result = -1;
  if (ext == ".pcd") {
    // PCL 1.13's PCDReader::read crashes on a file without a valid header: check it first.
    pcl::PCDReader reader;
    Eigen::Vector4f origin;
    Eigen::Quaternionf orientation;
    int version = 0, data_type = 0;
    unsigned int data_index = 0;
    if (reader.readHeader(path, blob, origin, orientation, version, data_type, data_index) < 0 ||
        blob.fields.empty())
      throw IOError("cloud '" + path + "' is not a valid .pcd file (bad header)");
    if (static_cast<std::size_t>(blob.width) * blob.height == 0)
      throw IOError("cloud '" + path + "' has no points");
    result = reader.read(path, blob);
  }
  else if (ext == ".ply")
    result = pcl::PLYReader().read(path, blob);
  else
    throw IOError("cloud '" + path + "' is neither .pcd nor .ply");
  if (result < 0)
    throw IOError("cloud '" + path + "' cannot be parsed as " + ext.substr(1));
}

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
