// msf_mesh: marching cubes over a TSDF volume written by msf_integrate; a welded, coloured
// mesh saved as binary PLY, OBJ or VTK by the output's extension.
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/cloud_io.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/console/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

const std::vector<std::string> kValueOptions = {"-min_weight", "-min_component_triangles", "-config", "-voxel", "-trunc"};

void printHelp(const char* name) {
  print_error("Syntax is: %s <volume.pcd> <mesh.ply|mesh.obj|mesh.vtk> [options]\n", name);
  print_info("  Extracts the zero surface of a TSDF volume (msf_integrate) by marching cubes. Options:\n");
  const msf::MarchingCubes::Config defaults; // the help says what the code does
  print_info("    -min_weight W   voxels with weight <= W (m^-2, an inverse variance) make no triangles (default ");
  print_value("%s", msf::configValue(defaults.min_weight).c_str()); print_info(")\n");
  print_info("    -min_component_triangles N\n"
             "                    remove connected pieces of fewer than N triangles (default ");
  print_value("%s", msf::configValue(defaults.min_component_triangles).c_str()); print_info("; 0 keeps all)\n");
  print_info("    -config FILE    YAML with a section marching_cubes; flags override it\n");
  print_info("    -voxel V -trunc T\n"
             "                    voxel size and truncation (m) of a volume whose header comment a PCL\n"
             "                    rewrite dropped (otherwise read from the file, and checked if given)\n");
}

int run(int argc, char** argv) {
  msf::tool::checkOptions(argc, argv, kValueOptions, {});
  const auto files = msf::tool::positionalArguments(argc, argv, kValueOptions);
  if (files.size() != 2) {
    printHelp(argv[0]);
    throw msf::InvalidInputError("need one input volume and one output mesh, got " + std::to_string(files.size()) +
                                 " file arguments");
  }
  const std::string ext = msf::fileExtension(files[1]);
  if (ext != ".ply" && ext != ".obj" && ext != ".vtk")
    throw msf::InvalidInputError("output mesh '" + files[1] + "' must end in .ply, .obj or .vtk");
  msf::MarchingCubes::Config config;
  std::string config_path;
  if (msf::tool::parseArgument(argc, argv, "-config", config_path) >= 0)
    msf::readConfigSection(config_path, "marching_cubes", config);
  msf::tool::parseArgument(argc, argv, "-min_weight", config.min_weight);
  msf::tool::parseArgument(argc, argv, "-min_component_triangles", config.min_component_triangles);
  msf::MarchingCubes mesher(config);

  pcl::console::TicToc tt;
  print_highlight("Loading ");
  print_value("%s ", files[0].c_str());
  tt.tic();
  double voxel = 0, trunc = 0;
  msf::tool::parseArgument(argc, argv, "-voxel", voxel);
  msf::tool::parseArgument(argc, argv, "-trunc", trunc);
  if (voxel < 0 || trunc < 0 || !std::isfinite(voxel) || !std::isfinite(trunc))
    throw msf::InvalidInputError("-voxel and -trunc must be > 0 m");
  const msf::TsdfVolume volume = msf::TsdfVolume::load(files[0], voxel, trunc);
  msf::tool::printDone(tt.toc(), volume.numObservedVoxels());

  print_highlight("Meshing ");
  tt.tic();
  pcl::PolygonMesh mesh;
  mesher.extract(volume, mesh);
  const double ms = tt.toc();
  print_info("[done, ");
  print_value("%g", ms);
  print_info(" ms : ");
  print_value("%u", mesh.cloud.width);
  print_info(" vertices, ");
  print_value("%zu", mesh.polygons.size());
  print_info(" triangles");
  const msf::MarchingCubes::Stats& stats = mesher.lastStats();
  if (config.min_component_triangles > 0) {
    print_info(", ");
    print_value("%zu", stats.components_removed);
    print_info(" small pieces of ");
    print_value("%zu", stats.triangles_removed);
    print_info(" triangles removed");
  }
  print_info("]\n");
  if (mesh.polygons.empty() && stats.triangles_removed > 0)
    throw msf::InvalidInputError("volume '" + files[0] + "': every piece of its surface has fewer than " +
                                 std::to_string(config.min_component_triangles) + " triangles: no mesh written");
  if (mesh.polygons.empty())
    throw msf::InvalidInputError("volume '" + files[0] + "' has no surface above weight " +
                                 std::to_string(config.min_weight) + ": no mesh written");

  print_highlight("Saving ");
  print_value("%s ", files[1].c_str());
  tt.tic();
  msf::saveMesh(files[1], mesh);
  msf::tool::printDone(tt.toc(), mesh.cloud.width);
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_mesh", 2, printHelp, [&] { return run(argc, argv); });
}
