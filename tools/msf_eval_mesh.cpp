// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_eval_mesh: a mesh against the true surface of synthetic sequences of one world (evaluation
// protocol 3): accuracy against gt/scene.ply, completeness of what their frames saw.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/io/cloud_io.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/seen_surface.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

using namespace pcl::console;

namespace {

bool sameBytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  return fa && fb && std::equal(std::istreambuf_iterator<char>(fa), std::istreambuf_iterator<char>(),
                                std::istreambuf_iterator<char>(fb), std::istreambuf_iterator<char>());
}

void writeJson(const std::string& path, const msf::MeshAccuracy& a, std::size_t sequences) {
  std::ostringstream json;
  json << "{\n  \"sequences\": " << sequences << ",\n  \"vertices\": " << a.vertices << ",\n  \"accuracy_mean_m\": "
       << a.accuracy_mean_m << ",\n  \"accuracy_median_m\": " << a.accuracy_median_m << ",\n  \"precision\": "
       << a.precision << ",\n  \"truth_samples\": " << a.truth_samples << ",\n  \"completeness\": " << a.completeness
       << ",\n  \"threshold_m\": " << a.threshold_m << "\n}\n";
  msf::writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << json.str();
    if (!out.flush())
      throw msf::IOError("cannot write '" + tmp + "'");
  });
}

} // namespace

int main(int argc, char** argv) {
  std::string frames = "0:", json;
  double max_depth_m = 0.0, threshold_m = 0.2; // 0: each sequence's rig's range
  bool overwrite = false;
  msf::tool::CommandLine cli(
      "msf_eval_mesh", "<mesh.ply> <synthetic sequence>... [options]",
      "Scores a mesh against the true surface of synthetic sequences of one world (msf_synth, the same -seed and "
      "-street_m): accuracy, the mean distance of the mesh's vertices to gt/scene.ply (capped at 1 m); completeness, "
      "the share of the static surface the sequences' frames saw (every 4th pixel of their exact depth up to "
      "-max_depth) within -threshold of the mesh. Scored against the same sequences, the meshes of single drives "
      "and of their merge compare.");
  cli.value("-frames", "a:b", frames, "the frames of each sequence that saw the surface (default {default})")
      .value("-max_depth", "M", max_depth_m,
             "the depth up to which a frame saw the surface (default: the range msf_reconstruct scores its map to on "
             "the sequence's rig, tsdf_integrator.max_depth_m adapted to it; 40 m on KITTI's)")
      .value("-threshold", "T", threshold_m, "completeness and precision distance (default {default} m)")
      .value("-o", "FILE", json, "also write the scores as JSON")
      .overwriteOption(overwrite);
  return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& args) {
    if ((cli.given("-max_depth") && !(max_depth_m > 0)) || !(threshold_m > 0))
      throw msf::InvalidInputError("-max_depth and -threshold must be > 0");
    msf::tool::requireNewOutputs({json}, overwrite);
    pcl::console::TicToc tt;
    tt.tic();
    print_highlight("Reading the truth ");
    msf::synthetic::SeenSurface seen;
    std::string scene;
    for (std::size_t k = 1; k < args.size(); ++k) {
      const msf::Sequence sequence(args[k]);
      if (sequence.groundTruthDir().empty())
        throw msf::InvalidInputError("'" + args[k] + "' is not a synthetic sequence (no gt/)");
      const std::string this_scene = msf::synthetic::GroundTruth(sequence.groundTruthDir()).sceneMeshPath();
      if (scene.empty())
        scene = this_scene;
      else if (!sameBytes(scene, this_scene))
        throw msf::InvalidInputError("'" + args[k] + "' is not of the world of '" + args[1] +
                                     "': their gt/scene.ply differ (msf_synth: the same -seed and -street_m)");
      // One yardstick: the range msf_reconstruct scores to on this rig (adaptToRig), unless given.
      const msf::PipelineConfig on_rig = msf::adaptToRig(msf::PipelineConfig(), sequence.calibration());
      const double depth_m = cli.given("-max_depth") ? max_depth_m : on_rig.integrator.max_depth_m;
      seen.add(sequence, sequence.indices(msf::FrameRange::parse(frames)), depth_m);
    }
    pcl::PolygonMesh truth, mesh;
    msf::loadMesh(scene, truth);
    msf::loadMesh(args[0], mesh);
    msf::tool::printDone(tt.toc(), seen.points.size(), "points");
    print_highlight("Scoring ");
    print_value("%s ", args[0].c_str());
    tt.tic();
    const msf::MeshAccuracy a = msf::evaluateMesh(mesh, truth, seen.points, threshold_m);
    msf::tool::printDone(tt.toc(), a.vertices, "vertices");
    print_info("accuracy %.4f m (median %.4f m), completeness %.2f %% and precision %.2f %% within %.2f m; %zu "
               "vertices, %zu samples of the seen surface\n",
               a.accuracy_mean_m, a.accuracy_median_m, 100 * a.completeness, 100 * a.precision, a.threshold_m,
               a.vertices, a.truth_samples);
    if (!json.empty())
      writeJson(json, a, args.size() - 1);
    return 0;
  });
}
