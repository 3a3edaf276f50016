// The main job: a KITTI sequence (or the built-in synthetic street) to a coloured mesh,
// with a report of speed and, where ground truth exists, accuracy.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/fusion/point_types.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/impl/organized_conversion.hpp> // depthImageToCloud for the fused point type
#include <msf/io/sequence.h>
#include <msf/pipeline/depth_panel.h>
#include <msf/pipeline/mesh_renderer.h>
#include <msf/pipeline/pipeline.h>
#include <msf/pipeline/run_report.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/synthetic_generator.h>

#include <opencv2/core.hpp>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) {
  g_stop = true;
  // A second Ctrl-C ends at once.
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

void printHelp(const char* name) {
  print_error("Syntax is: %s [DATASET_DIR] [options]\n", name);
  print_info("  Reconstructs a KITTI odometry sequence, a KITTI raw drive or a synthetic sequence (msf_synth)\n"
             "  into a coloured mesh: LiDAR projection + compound interpolation and SGBM stereo, fused per\n"
             "  pixel, integrated into a regularized TSDF, meshed by marching cubes. Without DATASET_DIR it\n"
             "  generates the default synthetic street (20 frames) in a temporary folder and reconstructs it.\n");
  print_info("  where options are:\n");
  print_info("    -o DIR         output folder (default msf_out): mesh.ply, volume.pcd, summary.json,\n"
             "                   frames.csv, runtime.png, depth_NNNNNN.png, mesh_preview.png, report.md\n");
  print_info("    -config FILE   YAML configuration (config/kitti.yaml); flags below override it\n");
  print_info("    -frames a:b    frame range, inclusive (default: all)\n");
  print_info("    -voxel V       voxel size in metres (tsdf_volume.voxel_size_m)\n");
  print_info("    -lambda L      regularization of eq. 7 (tsdf_integrator.lambda)\n");
  print_info("    -panels N      depth panels to draw, spread over the frames (default 3)\n");
  print_info("    -save_depth    also write each frame's fused depth as OUT/depth/NNNNNN.pcd\n");
  print_info("  Ctrl-C stops after the frames under way and still writes the mesh and the summary.\n");
}

/// Ground truth of a synthetic sequence, accumulated over the run.
struct GroundTruthScores {
  std::unique_ptr<msf::synthetic::GroundTruth> truth;
  std::map<std::string, msf::DepthErrorAccumulator> all, background, foreground;
  std::vector<Eigen::Vector3f> seen_surface;  // ground-truth depth back-projected to the world

  void add(const msf::FrameResult& r, const msf::Calibration& calibration, double max_depth_m) {
    const std::size_t gt_index = truth->indexOf(r.name);
    const cv::Mat gt = truth->depth(gt_index);
    const cv::Mat fg = truth->foregroundMask(gt_index), bg = truth->backgroundMask(gt_index);
    const double fb = calibration.focalBaseline();
    const std::pair<const char*, cv::Mat> methods[] = {
        {"sgbm", r.stereo_depth}, {"interpolated", r.lidar_depth}, {"fused", r.fused.depth}};
    for (const auto& [name, estimate] : methods) {
      all[name].add(gt, estimate, fb);
      background[name].add(gt, estimate, fb, bg);
      foreground[name].add(gt, estimate, fb, fg);
    }
    // Every 4th pixel of the true surface in range, for the mesh's completeness.
    const float fx = static_cast<float>(calibration.fx()), fy = static_cast<float>(calibration.fy());
    const float cx = static_cast<float>(calibration.cx()), cy = static_cast<float>(calibration.cy());
    const Eigen::Isometry3f T = r.T_world_cam0.cast<float>();
    for (int v = 0; v < gt.rows; v += 4)
      for (int u = 0; u < gt.cols; u += 4) {
        const float z = gt.at<float>(v, u);
        if (z > 0.f && z <= max_depth_m)
          seen_surface.push_back(T * Eigen::Vector3f((u - cx) * z / fx, (v - cy) * z / fy, z));
      }
  }
};

/// The fused depth as msf_fuse writes it: an organized cloud with colour and weight.
pcl::PointCloud<msf::PointXYZRGBWeight> fusedCloud(const msf::DepthFrame& fused, const msf::Calibration& calibration) {
  pcl::PointCloud<msf::PointXYZRGBWeight> cloud;
  msf::depthImageToCloud(fused.depth, calibration, 0, cloud);
  for (int v = 0; v < fused.depth.rows; ++v)
    for (int u = 0; u < fused.depth.cols; ++u) {
      msf::PointXYZRGBWeight& p = cloud.at(u, v);
      const cv::Vec3b bgr = fused.color.at<cv::Vec3b>(v, u);
      p.b = bgr[0];
      p.g = bgr[1];
      p.r = bgr[2];
      p.a = 255;
      p.weight = fused.weight.at<float>(v, u);
    }
  return cloud;
}

class Progress {
public:
  explicit Progress(std::size_t total) : total_(total), tty_(::isatty(STDOUT_FILENO)), start_(Clock::now()) {}
  void frame(const msf::FrameResult& r, std::size_t done) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const double fps = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    const double left = fps > 0 ? static_cast<double>(total_ - done) / fps : 0.0;
    if (tty_) {
      std::printf("\r  frame %zu/%zu  %.1f fps  %.0f s left   ", done, total_, fps, left);
      if (done == total_)
        std::printf("\n");
    } else {
      std::printf("  frame %s (%zu/%zu): depth %.1f ms, fusion %.1f ms, integrate %.1f ms, %.1f fps\n",
                  r.name.c_str(), done, total_, r.times.depth_ms, r.times.fusion_ms, r.times.integrate_ms, fps);
    }
    std::fflush(stdout);
  }
  void end() {
    if (tty_)
      std::printf("\n");
  }

private:
  using Clock = std::chrono::steady_clock;
  std::size_t total_;
  bool tty_;
  Clock::time_point start_;
};

/// Indices of `count` frames spread over `frames` (first, ..., last).
std::set<std::size_t> spread(const std::vector<std::size_t>& frames, int count) {
  std::set<std::size_t> chosen;
  if (frames.empty() || count <= 0)
    return chosen;
  for (int k = 0; k < count; ++k)
    chosen.insert(frames[count == 1 ? 0 : (frames.size() - 1) * k / (count - 1)]);
  return chosen;
}

std::string generateDefaultStreet(const std::string& dir) {
  msf::synthetic::SyntheticConfig config;
  config.frames = 20;
  print_highlight("No dataset given: generating the default synthetic street (%d frames) in ", config.frames);
  print_value("%s\n", dir.c_str());
  const msf::synthetic::SyntheticGenerator generator(config);
  TicToc tt;
  tt.tic();
  generator.writeDataset(dir);
  print_info("  generated in %.1f s\n", tt.toc() / 1000.0);
  return dir;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_reconstruct", 1, printHelp, [&] {
    const std::vector<std::string> value_options{"-o", "-config", "-frames", "-voxel", "-lambda", "-panels"};
    msf::tool::checkOptions(argc, argv, value_options, {"-save_depth"});
    const auto positional = msf::tool::positionalArguments(argc, argv, value_options);
    if (positional.size() > 1)
      throw msf::InvalidInputError("expected at most one DATASET_DIR (see -h)");

    std::string out = "msf_out", config_path, frames_text = "0:";
    int panels = 3;
    msf::tool::parseArgument(argc, argv, "-o", out);
    msf::tool::parseArgument(argc, argv, "-config", config_path);
    msf::tool::parseArgument(argc, argv, "-frames", frames_text);
    msf::tool::parseArgument(argc, argv, "-panels", panels);
    const bool save_depth = find_switch(argc, argv, "-save_depth");
    msf::PipelineConfig config = msf::PipelineConfig::load(config_path);
    if (find_argument(argc, argv, "-voxel") >= 0)
      msf::tool::parseArgument(argc, argv, "-voxel", config.volume.voxel_size_m);
    if (find_argument(argc, argv, "-lambda") >= 0)
      msf::tool::parseArgument(argc, argv, "-lambda", config.integrator.lambda);
    config.validate();
    const msf::FrameRange range = msf::FrameRange::parse(frames_text);

    msf::ensureOutputDirectory(out);
    if (save_depth)
      fs::create_directories(fs::path(out) / "depth");

    // The dataset, or the default synthetic street in a temporary folder removed at the end.
    std::string dataset;
    std::unique_ptr<fs::path, void (*)(fs::path*)> temporary(nullptr, [](fs::path* p) {
      std::error_code e;
      fs::remove_all(*p, e);
      delete p;
    });
    if (positional.empty()) {
      char pattern[] = "/tmp/msf_street_XXXXXX";
      if (!::mkdtemp(pattern))
        throw msf::IOError("cannot create a temporary folder in /tmp");
      temporary.reset(new fs::path(pattern));
      dataset = generateDefaultStreet((*temporary / "street").string());
    } else {
      dataset = positional.front();
    }

    const msf::Sequence sequence(dataset);
    if (!sequence.hasPoses())
      throw msf::InvalidInputError("sequence '" + sequence.directory() +
                                   "' has no poses (odometry poses/XX.txt or raw oxts/): the map needs them");
    const std::vector<std::size_t> frames = sequence.indices(range);
    const msf::Calibration& calibration = sequence.calibration();

    msf::RunReport report;
    report.dataset = sequence.directory();
    report.layout = !sequence.groundTruthDir().empty()            ? "synthetic"
                    : sequence.layout() == msf::Sequence::Layout::Raw ? "raw"
                                                                    : "odometry";
    report.frames_requested = frames.size();
    report.voxel_size_m = config.volume.voxel_size_m;
    report.lambda = config.integrator.lambda;

    GroundTruthScores scores;
    if (!sequence.groundTruthDir().empty())
      scores.truth = std::make_unique<msf::synthetic::GroundTruth>(sequence.groundTruthDir());

    print_highlight("Reconstructing ");
    print_value("%zu", frames.size());
    print_info(" frames of ");
    print_value("%s", sequence.directory().c_str());
    print_info(" into ");
    print_value("%s\n", out.c_str());

    msf::Pipeline pipeline(calibration, config);
    const std::set<std::size_t> panel_frames = spread(frames, panels);
    pipeline.setKeepSparse(!panel_frames.empty()); // the panels show the projected scan
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    Progress progress(frames.size());

    const auto stats = pipeline.run(
        sequence, frames,
        [&](msf::FrameResult& r) {
          report.frames.push_back({r.index, r.name, r.times,
                                   r.times.load_ms + r.times.depth_ms + r.times.fusion_ms + r.times.integrate_ms});
          if (scores.truth)
            scores.add(r, calibration, config.integrator.max_depth_m);
          if (save_depth)
            msf::saveCloud((fs::path(out) / "depth" / (r.name + ".pcd")).string(), fusedCloud(r.fused, calibration));
          if (panel_frames.count(r.index)) {
            const cv::Mat& fused = r.fused.depth;
            msf::DepthPanel panel;
            panel.addImage("left image (camera 0), frame " + r.name, r.left);
            if (!r.lidar_sparse.empty())
              panel.addDepth("projected LiDAR", r.lidar_sparse, 3.f, 60.f, 1);
            panel.addDepth("interpolated LiDAR", r.lidar_depth, 3.f, 60.f);
            panel.addDepth("SGBM", r.stereo_depth, 3.f, 60.f);
            panel.addDepth("fused", fused, 3.f, 60.f);
            if (scores.truth)
              panel.addError("|fused - ground truth|", fused, scores.truth->depth(scores.truth->indexOf(r.name)), 2.f);
            const std::string name = "depth_" + r.name + ".png";
            msf::writeImage((fs::path(out) / name).string(), panel.render());
            report.depth_panels.push_back(name);
          }
          progress.frame(r, report.frames.size());
        },
        &g_stop);
    progress.end();
    report.wall_s = stats.wall_s;
    report.first_frame_s = stats.first_frame_s;
    report.interrupted = stats.interrupted;
    if (stats.interrupted)
      print_warn("Interrupted after %zu of %zu frames: writing what was integrated.\n", stats.frames_done, frames.size());

    TicToc tt;
    tt.tic();
    print_highlight("Meshing ");
    const msf::TriangleMesh& mesh = pipeline.updateMesh();
    report.mesh_ms = tt.toc();
    msf::tool::printDone(report.mesh_ms, mesh.triangles.size());
    report.vertices = mesh.vertices.size();
    report.triangles = mesh.triangles.size();
    report.pieces_removed = pipeline.meshStats().components_removed;
    report.triangles_removed = pipeline.meshStats().triangles_removed;
    report.observed_voxels = pipeline.volume().numObservedVoxels();
    report.blocks = pipeline.volume().numBlocks();
    report.volume_memory_mb = static_cast<double>(pipeline.volume().memoryBytes()) / (1024.0 * 1024.0);

    tt.tic();
    print_highlight("Saving ");
    print_value("%s/{mesh.ply, volume.pcd} ", out.c_str());
    pcl::PolygonMesh polygon_mesh;
    mesh.toPolygonMesh(polygon_mesh);
    if (!mesh.triangles.empty()) {
      msf::saveMesh((fs::path(out) / report.mesh_file).string(), polygon_mesh);
      pipeline.volume().save((fs::path(out) / report.volume_file).string());
    } else {
      print_warn("\nno surface was reconstructed: mesh.ply and volume.pcd are not written\n");
    }
    msf::tool::printDone(tt.toc(), mesh.vertices.size());

    if (!mesh.triangles.empty()) {
      // Preview: from above, and from the first frame's camera.
      const cv::Size size = calibration.requireImageSize();
      const Eigen::Isometry3d first_pose = sequence.poses()[frames.front()];
      cv::Mat above = msf::MeshRenderer::renderFromAbove(mesh, -(first_pose.linear().col(1)),
                                                         cv::Size(size.width, size.width / 2));
      cv::Mat camera = msf::MeshRenderer::render(mesh, first_pose, calibration.fx(), calibration.fy(),
                                                 calibration.cx(), calibration.cy(), size);
      cv::Mat preview;
      cv::vconcat(above, camera, preview);
      report.preview_file = "mesh_preview.png";
      msf::writeImage((fs::path(out) / report.preview_file).string(), preview);
    }

    if (scores.truth) {
      for (const auto& [name, acc] : scores.all) {
        auto& d = report.depth[name];
        d.all = acc.metrics();
        d.background = scores.background[name].metrics();
        d.foreground = scores.foreground[name].metrics();
        d.has_split = true;
      }
      const std::string scene = scores.truth->sceneMeshPath();
      if (!mesh.triangles.empty() && fs::exists(scene)) {
        tt.tic();
        print_highlight("Scoring the mesh against ");
        print_value("%s ", scene.c_str());
        pcl::PolygonMesh truth;
        msf::loadMesh(scene, truth);
        report.mesh_accuracy = msf::evaluateMesh(polygon_mesh, truth, scores.seen_surface,
                                                 2.0 * config.volume.voxel_size_m, 1.0);
        report.has_mesh_accuracy = true;
        msf::tool::printDone(tt.toc(), report.mesh_accuracy.vertices);
      }
    }
    report.peak_memory_mb = msf::peakMemoryMb();
    report.writeFramesCsv((fs::path(out) / "frames.csv").string());
    if (!report.frames.empty())
      report.writeRuntimePlot((fs::path(out) / "runtime.png").string());
    report.writeSummaryJson((fs::path(out) / "summary.json").string());
    report.writeMarkdown((fs::path(out) / "report.md").string());

    print_info("%zu frames in %.2f s: ", report.frames.size(), report.wall_s);
    print_value("%.1f fps", report.framesPerSecond());
    if (report.frames.size() > 1)
      print_info(" (%.1f after the first frame)", report.framesPerSecondAfterFirst());
    print_info(", peak memory %.0f MiB, %zu triangles\n", report.peak_memory_mb, report.triangles);
    for (const auto& [name, d] : report.depth)
      print_info("  %-12s D1 %.2f %% (missing = bad), depth MAE %.3f m, coverage %.3f\n", name.c_str(),
                 100 * d.all.d1_all, d.all.mae_m, d.all.coverage);
    if (report.has_mesh_accuracy)
      print_info("  mesh: accuracy %.3f m, completeness %.1f %% within %.2f m\n", report.mesh_accuracy.accuracy_mean_m,
                 100 * report.mesh_accuracy.completeness, report.mesh_accuracy.threshold_m);
    print_info("Report: ");
    print_value("%s/report.md\n", out.c_str());
    return stats.interrupted ? 130 : 0;
  });
}
