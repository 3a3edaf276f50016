// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_mesh: marching cubes over a TSDF volume written by msf_integrate; a welded, coloured
// mesh saved as binary PLY, OBJ or VTK by the output's extension.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/cloud_io.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/console/time.h>
#include <pcl/console/print.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

/// What the command line sets.
struct Settings {
  msf::MarchingCubes::Config config;
  double voxel = 0, trunc = 0;
  std::string region;
  bool overwrite = false;
};

/// A streamed store: tile by tile (the small-piece filter is not applied across tiles).
int remeshStore(const std::string& store, const std::string& output, const Settings& settings,
                const msf::tool::CommandLine& cli) {
  const msf::MarchingCubes::Config& config = settings.config;
  const std::string& region = settings.region;
  if (msf::fileExtension(output) != ".ply")
    throw msf::InvalidInputError("output mesh '" + output + "': a store is meshed into a .ply");
  if (cli.given("-min_component_triangles") && config.min_component_triangles > 0)
    throw msf::InvalidInputError("-min_component_triangles: a store is meshed tile by tile, pieces cross tiles");
  if (config.min_component_triangles > 0)
    print_info("A store keeps its small pieces (marching_cubes.min_component_triangles is not applied): it is "
               "meshed tile by tile, and a piece may cross tiles\n");
  if (cli.given("-voxel") || cli.given("-trunc"))
    throw msf::InvalidInputError("-voxel and -trunc are for a volume .pcd: a store's index gives them");
  Eigen::Vector3d lo = Eigen::Vector3d::Ones(), hi = Eigen::Vector3d::Zero();
  if (cli.given("-region")) {
    std::vector<double> v;
    std::stringstream ss(region);
    std::string item;
    while (std::getline(ss, item, ',')) {
      char* end = nullptr;
      const double x = std::strtod(item.c_str(), &end);
      if (item.empty() || *end != '\0' || !std::isfinite(x))
        throw msf::InvalidInputError("-region: '" + item + "' is not a number");
      v.push_back(x);
    }
    if (v.size() != 6 || v[0] > v[3] || v[1] > v[4] || v[2] > v[5])
      throw msf::InvalidInputError("-region: need x0,y0,z0,x1,y1,z1 with x0 <= x1, y0 <= y1, z0 <= z1, got '" + region +
                                   "'");
    lo = Eigen::Vector3d(v[0], v[1], v[2]);
    hi = Eigen::Vector3d(v[3], v[4], v[5]);
  }
  pcl::console::TicToc tt;
  print_highlight("Meshing the store ");
  print_value("%s ", store.c_str());
  print_info("tile by tile into ");
  print_value("%s ", output.c_str());
  tt.tic();
  const std::size_t triangles = msf::StreamingMap::remesh(store, config, output, lo, hi);
  msf::tool::printDone(tt.toc(), triangles, "triangles");
  if (triangles == 0)
    throw msf::InvalidInputError("store '" + store + "' has no surface above weight " +
                                 std::to_string(config.min_weight) + (region.empty() ? "" : " in the region") +
                                 ": no mesh written");
  return 0;
}

int run(const msf::tool::CommandLine& cli, const msf::tool::Arguments& files, const Settings& settings,
        const char* program) {
  if (files.size() != 2) {
    cli.printHelp(program);
    throw msf::InvalidInputError("need one input volume and one output mesh, got " + std::to_string(files.size()) +
                                 " file arguments");
  }
  const std::string ext = msf::fileExtension(files[1]);
  if (ext != ".ply" && ext != ".obj" && ext != ".vtk")
    throw msf::InvalidInputError("output mesh '" + files[1] + "' must end in .ply, .obj or .vtk");
  msf::tool::requireNewOutputs({files[1]}, settings.overwrite);
  const msf::MarchingCubes::Config& config = settings.config;
  msf::MarchingCubes mesher(config);
  if (std::filesystem::is_directory(files[0]))
    return remeshStore(files[0], files[1], settings, cli);
  if (cli.given("-region"))
    throw msf::InvalidInputError("-region applies to a store folder (msf_reconstruct -stream), not to a volume .pcd");

  pcl::console::TicToc tt;
  print_highlight("Loading ");
  print_value("%s ", files[0].c_str());
  tt.tic();
  const double voxel = settings.voxel, trunc = settings.trunc;
  if (voxel < 0 || trunc < 0 || !std::isfinite(voxel) || !std::isfinite(trunc))
    throw msf::InvalidInputError("-voxel and -trunc must be > 0 m");
  const msf::TsdfVolume volume = msf::TsdfVolume::load(files[0], voxel, trunc);
  msf::tool::printDone(tt.toc(), volume.numObservedVoxels(), "voxels");

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
  msf::tool::printDone(tt.toc(), mesh.cloud.width, "vertices");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::MarchingCubes::Config& config = settings.config;
  msf::tool::CommandLine cli(
      "msf_mesh", "<volume.pcd | STORE_DIR> <mesh.ply|mesh.obj|mesh.vtk> [options]",
      "Extracts the zero surface of a TSDF volume (msf_integrate) by marching cubes. STORE_DIR is the output folder "
      "of msf_reconstruct -stream (its tsdf/index.txt and block files): meshed tile by tile in bounded memory into "
      "mesh.ply (a PLY only) and its tiles into mesh.ply.tiles/.");
  cli.value("-config", "FILE", [&](const std::string& path) { msf::readConfigSection(path, config); },
            "YAML with a section marching_cubes; the options below override it")
      .value("-min_weight", "W", config.min_weight,
             "voxels with weight <= W (m^-2, an inverse variance) make no triangles (default {default})")
      .value("-max_unseen_corners", "N", config.max_unseen_corners,
             "mesh a cube with up to N corners no frame reached, the others on both sides of the surface, with them "
             "behind it (0..4; default {default}, 0 = off)")
      .value("-smoothing_lambda", "L", config.smoothing_lambda,
             "eq. 7 at meshing, each voxel's data term weighed by its weight (m^-2; default {default}, 0 = off)")
      .value("-min_component_triangles", "N", config.min_component_triangles,
             "remove connected pieces of fewer than N triangles (default {default}; 0 keeps all)")
      .value("-component_keep_weight", "W", config.component_keep_weight,
             "... but keep a piece with a vertex of weight >= W (m^-2; default {default}; 0: none is kept for it)")
      .value("-min_component_extent_voxels", "N", config.min_component_extent_voxels,
             "... unless it is closed and fits in a box of N voxels a side (default {default}; 0: off)")
      .value("-component_release_passes", "N", config.component_release_passes,
             "... unless rays passed the voxel behind that vertex N frames in a row since it saw a surface, as where "
             "a car stood (0..3; default {default}, 0 = never)")
      .value("-voxel", "V", settings.voxel,
             "voxel size (m) of a volume whose header comment a PCL rewrite dropped (otherwise read from the file, "
             "and checked if given)")
      .value("-trunc", "T", settings.trunc, "its truncation (m), as -voxel")
      .value("-region", "x0,y0,z0,x1,y1,z1", settings.region,
             "a store's tiles within this box only (metres, world frame)")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 1,
                 [&](const msf::tool::Arguments& files) { return run(cli, files, settings, argv[0]); });
}
