// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_merge: the TSDF stores of several drives of one world (msf_reconstruct -stream) merged
// into one map, tile by tile, in this process (msf_batch runs the same merge as tasks).
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/tool.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/reconstruction/store_merge.h>
#include <msf/reconstruction/streaming_map.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

void writeSummary(const std::string& path, const msf::StoreMerge& merge, const msf::StoreMerge::Stats& s,
                  std::size_t triangles, double mesh_ms) {
  std::ostringstream json;
  json << "{\n  \"stores\": " << merge.stores().size() << ",\n  \"tiles\": " << s.tiles << ",\n  \"tiles_shared\": "
       << s.tiles_shared << ",\n  \"blocks\": " << s.blocks << ",\n  \"blocks_shared\": " << s.blocks_shared
       << ",\n  \"voxels_shared\": " << s.voxels_shared << ",\n  \"voxels_capped\": " << s.voxels_capped
       << ",\n  \"max_weight\": " << merge.config().max_weight << ",\n  \"merge_s\": " << s.ms / 1000.0
       << ",\n  \"mesh_s\": " << mesh_ms / 1000.0 << ",\n  \"triangles\": " << triangles << "\n}\n";
  msf::writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << json.str();
    if (!out.flush())
      throw msf::IOError("cannot write '" + tmp + "'");
  });
}

} // namespace

int main(int argc, char** argv) {
  std::string out, config_path;
  msf::PipelineConfig config;
  msf::tool::CommandLine cli(
      "msf_merge", "-o MAP STORE STORE... [options]",
      "Merges the TSDF stores of drives whose poses share a world (output folders of msf_reconstruct -stream, with "
      "tsdf/index.txt) into one map, tile by tile: each voxel the TSDF's weighted mean over the drives that observed "
      "it (distance and colour by weight, weights summed and capped at tsdf_integrator.max_weight); then meshes it "
      "tile by tile. MAP gets tsdf/, tiles/, mesh.ply (their welded union) and summary.json. msf_batch runs the same "
      "merge as tasks of a batch (docs/batch.md).");
  cli.value("-o", "MAP", out, "output folder (absent, empty, or an earlier msf_merge output, which is replaced)")
      .value("-config", "FILE", [&](const std::string& path) {
               config = msf::PipelineConfig::load(path);
               config_path = path;
             },
             "YAML configuration (the drives'): tsdf_integrator.max_weight and the marching_cubes section")
      .value("-max_weight", "W", config.integrator.max_weight,
             "cap of a merged voxel's weight (tsdf_integrator.max_weight, default {default})");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& stores) {
    if (out.empty())
      throw msf::InvalidInputError("no output folder: give -o MAP");
    config.validate();
    msf::StoreMerge::Config merge_config;
    merge_config.max_weight = config.integrator.max_weight;
    pcl::console::TicToc tt;
    print_highlight("Reading the indexes of %zu stores ", stores.size());
    tt.tic();
    const msf::StoreMerge merge(stores, merge_config);
    msf::tool::printDone(tt.toc(), merge.tiles().size(), "tiles");

    std::vector<std::string> inputs = stores;
    inputs.push_back(config_path);
    msf::OutputFolder folder(out, "msf_merge", inputs);
    print_highlight("Merging the tiles ");
    msf::TsdfStore merged = merge.outputStore(folder.dir());
    const msf::StoreMerge::Stats stats = merge.merge(merge.tiles(), merged);
    merge.writeIndex(merged);
    print_info("[done, ");
    print_value("%g", stats.ms);
    print_info(" ms : ");
    print_value("%zu", stats.tiles);
    print_info(" tiles, %zu held by several stores; %zu voxels observed by several, %zu of them capped]\n",
               stats.tiles_shared, stats.voxels_shared, stats.voxels_capped);

    print_highlight("Meshing the tiles ");
    tt.tic();
    const std::string tiles = folder.dir() + "/tiles";
    fs::create_directories(tiles);
    msf::StreamingMap::meshTiles(merged, config.mesher, merged.tiles(), tiles);
    const std::size_t triangles = msf::StreamingMap::unionOfTiles(merged, merged.tiles(), tiles, folder.dir() + "/mesh.ply");
    const double mesh_ms = tt.toc();
    msf::tool::printDone(mesh_ms, triangles, "triangles");
    if (triangles == 0)
      throw msf::InvalidInputError("the merged map has no surface above weight " +
                                   std::to_string(config.mesher.min_weight) + ": nothing is written to '" + out + "'");
    writeSummary(folder.dir() + "/summary.json", merge, stats, triangles, mesh_ms);
    folder.commit();
    print_info("Map: ");
    print_value("%s/mesh.ply\n", out.c_str());
    return 0;
  });
}
