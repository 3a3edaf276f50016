// The main job: a KITTI sequence (or the built-in synthetic street) to a coloured mesh,
// with a report of speed and, where ground truth exists, accuracy.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/ghost_metric.h>
#include <msf/evaluation/holdout.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/evaluation/trajectory_plot.h>
#include <msf/fusion/point_types.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/impl/organized_conversion.hpp> // depthImageToCloud for the fused point type
#include <msf/io/sequence.h>
#include <msf/pipeline/depth_panel.h>
#include <msf/pipeline/mesh_renderer.h>
#include <msf/pipeline/pipeline.h>
#include <msf/pipeline/pose_source.h>
#include <msf/pipeline/run_report.h>
#include <msf/pipeline/source_depth_frame.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/synthetic_generator.h>

#include <opencv2/core.hpp>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>     // AT_FDCWD
#include <signal.h>    // kill, sigaction
#include <stdio.h>     // renameat2, RENAME_EXCHANGE
#include <unistd.h>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

constexpr int kMaxPanels = 100;

// Stop signals (SIGINT, SIGTERM, SIGHUP, SIGPIPE). None ends the process before the mesh and
// the summary are written: the first stops the run after the frames under way; the second
// also skips the optional work after the mesh (its scores, the renderings, the single-source
// maps), what can take minutes on a long drive; later ones are only acknowledged. Ending at
// once is SIGKILL's job, and it leaves OUT as it was.
void installStopHandler() {
  msf::tool::installStopSignals(
      {"msf_reconstruct: stopping after the frames under way; the mesh and the summary are still written (again: "
       "also skip the mesh's scores and renderings)",
       "msf_reconstruct: skipping the mesh's scores and renderings; writing the mesh and the summary (kill -9 ends "
       "at once and leaves the output folder as it was)",
       "msf_reconstruct: still writing the mesh and the summary (kill -9 ends at once and leaves the output folder "
       "as it was)"});
}

/// After a second stop signal: the optional work after the mesh is skipped.
bool hurried() { return msf::tool::stopRequests() >= 2; }

/// Ground truth of a synthetic sequence, accumulated over the run.
struct GroundTruthScores {
  std::unique_ptr<msf::synthetic::GroundTruth> truth;
  std::map<std::string, msf::DepthErrorAccumulator> all, background, foreground;
  std::vector<Eigen::Vector3f> seen_surface;  // ground-truth depth back-projected to the world
  std::vector<float> seen_depth;              // the depth each was seen at
  pcl::PolygonMesh scene;                     // gt/scene.ply, read before the run
  std::optional<msf::SurfaceClasses> classes; // gt/scene_classes.txt, when the dataset has it
  /// For the mesh's completeness; not for a streamed map (no mesh scores): it grows by ~0.4 MB
  /// a frame, what a drive in bounded memory cannot keep.
  bool keep_surface = true;

  /// One method's depth of frame `name` against its ground truth `gt`: all, background, foreground.
  void addDepth(const std::string& method, const std::string& name, const cv::Mat& gt, const cv::Mat& estimate,
                double focal_baseline) {
    const std::size_t gt_index = truth->indexOf(name);
    all[method].add(gt, estimate, focal_baseline);
    background[method].add(gt, estimate, focal_baseline, truth->backgroundMask(gt_index));
    foreground[method].add(gt, estimate, focal_baseline, truth->foregroundMask(gt_index));
  }

  void add(const msf::FrameResult& r, const cv::Mat& gt, const msf::Calibration& calibration, double max_depth_m) {
    const std::size_t gt_index = truth->indexOf(r.name);
    const double fb = calibration.focalBaseline();
    const std::pair<const char*, cv::Mat> methods[] = {
        {"sgbm", r.stereo_depth}, {"interpolated", r.lidar_depth}, {"fused", r.fused.depth}};
    for (const auto& [name, estimate] : methods)
      addDepth(name, r.name, gt, estimate, fb);
    // Every 4th pixel of the true static surface in range, for the mesh's completeness against
    // gt/scene.ply: a moving car's pixels are where it was at that frame, not part of the map.
    if (!keep_surface)
      return;
    const cv::Mat moving = truth->movingMask(gt_index);
    const float fx = static_cast<float>(calibration.fx()), fy = static_cast<float>(calibration.fy());
    const float cx = static_cast<float>(calibration.cx()), cy = static_cast<float>(calibration.cy());
    const Eigen::Isometry3f T = r.T_world_cam0.cast<float>();
    for (int v = 0; v < gt.rows; v += 4)
      for (int u = 0; u < gt.cols; u += 4) {
        const float z = gt.at<float>(v, u);
        if (z > 0.f && z <= max_depth_m && moving.at<std::uint8_t>(v, u) == 0) {
          seen_surface.push_back(T * Eigen::Vector3f((u - cx) * z / fx, (v - cy) * z / fy, z));
          seen_depth.push_back(z);
        }
      }
  }
};

/// Why a ghost figure is absent, in words for the report.
std::string noGhostsReason(const msf::synthetic::GroundTruth* truth) {
  if (!truth)
    return "no synthetic ground truth: the places of moving objects are unknown";
  return "the dataset has no moving-object boxes (gt/moving_objects.txt)";
}

/// Ground truth made on the loading thread (the held-out rings of a frame), waiting there
/// until the integration thread scores the frame: only frames that were integrated are scored.
class PendingTruth {
public:
  void put(std::size_t frame, cv::Mat depth) {
    const std::lock_guard<std::mutex> lock(mutex_);
    depth_[frame] = std::move(depth);
  }
  cv::Mat take(std::size_t frame) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = depth_.find(frame);
    if (it == depth_.end())
      throw msf::InvalidInputError("frame " + std::to_string(frame) + " has no held-out ground truth");
    cv::Mat depth = std::move(it->second);
    depth_.erase(it);
    return depth;
  }

private:
  std::mutex mutex_;
  std::map<std::size_t, cv::Mat> depth_;
};

/// Splits a frame's scan for protocol 4: the input rings replace the scan; the held-out ones,
/// projected into camera 0, are returned. Throws InvalidInputError naming the frame's scan
/// when no ring is held out (a scan not in the sensor's order, ring after ring).
cv::Mat holdOutRings(msf::Frame& frame, const msf::Sequence& sequence, const msf::HoldoutConfig& config) {
  const msf::HoldoutFrame split = msf::makeHoldoutFrame(frame, sequence.calibration(), config);
  if (split.heldout_points == 0)
    throw msf::InvalidInputError("-holdout: scan '" + sequence.scanPath(frame.index) + "' has " +
                                 std::to_string(split.ring_count) + " ring id(s) and none is held out (rings.modulo " +
                                 std::to_string(config.rings.modulo) + ", heldout_remainder " +
                                 std::to_string(config.rings.heldout_remainder) +
                                 "): the ring hold-out needs a scan in the sensor's order, ring after ring");
  frame.scan = pcl::make_shared<pcl::PointCloud<pcl::PointXYZI>>(*split.input.scan);
  return split.gt_depth;
}

/// A single-source map of -compare_sources: its own volume and integrator, configured as
/// the pipeline's.
struct SourceMap {
  msf::DepthSource source;
  msf::TsdfVolume volume;
  msf::TsdfIntegrator integrator;
  msf::TriangleMesh mesh;
  SourceMap(msf::DepthSource s, const msf::PipelineConfig& config)
      : source(s), volume(config.volume.voxel_size_m, config.volume.truncation_m), integrator(volume, config.integrator) {
    volume.setMaxMemoryMb(config.volume.max_memory_mb);
  }
  std::string name() const { return std::string("mesh_") + msf::toString(source); }
};

/// The paper as published beside the run (-compare_paper): PipelineConfig::paper() with the
/// run's grid and rings, its own steps 1-5 on the same frames (loaded again, the same rings
/// held out, at the same poses) and its own map.
struct PaperRun {
  msf::PipelineConfig config;
  msf::Pipeline pipeline;
  PaperRun(const msf::Calibration& calibration, const msf::PipelineConfig& ours)
      : config(paperBeside(ours)), pipeline(calibration, config) {}
  static msf::PipelineConfig paperBeside(const msf::PipelineConfig& ours) {
    msf::PipelineConfig c = msf::PipelineConfig::paper();
    c.volume = ours.volume;
    c.rings = ours.rings;
    c.validate();
    return c;
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
  generator.writeDataset(dir, [](std::size_t, double, std::size_t) {
    if (msf::tool::stopFlag())
      throw msf::InvalidInputError("interrupted while generating the default street: nothing was written");
  });
  print_info("  generated in %.1f s\n", tt.toc() / 1000.0);
  return dir;
}

/// The console's protocol 4 table: per source, coverage, D1 (missing = bad) and MAE within
/// the map's range and over all ground-truth pixels (static ones, when the dataset says which).
void printMapEvaluation(const msf::RunReport::MapEvaluation& e) {
  print_info("Protocol 4, %s: %zu pixels in %zu frames; within range: true depth <= %g m%s\n", e.truth.c_str(),
             e.gt_pixels, e.frames, e.range_m, e.moving_split ? "; static pixels" : "");
  print_info("  %-12s %9s %8s %8s   %9s %8s %8s\n", "source", "coverage", "D1", "MAE m", "coverage", "D1", "MAE m");
  print_info("  %-12s %27s   %27s\n", "", "---- within range ----", "--------- all ---------");
  for (const auto& r : e.rows) {
    const msf::DepthMetrics &a = r.score.within_range, &b = r.score.all;
    print_info("  %-12s %9.3f %7.2f%% %8.3f   %9.3f %7.2f%% %8.3f", r.score.source.c_str(), a.coverage,
               100 * a.d1_all, a.mae_m, b.coverage, 100 * b.d1_all, b.mae_m);
    if (r.has_accuracy)
      print_info("   accuracy %.3f m, completeness %.1f %%", r.accuracy.accuracy_mean_m, 100 * r.accuracy.completeness);
    if (r.has_ghosts)
      print_info(", ghosts %.2f %%", 100 * r.ghosts.share);
    print_info("\n");
  }
  // The fused mesh's surest surface as complete as each other mesh (its weight curve).
  if (const auto* fused = e.fusedCurveRow())
    for (const auto& other : e.rows)
      if (&other != fused && other.has_accuracy) {
        const msf::WeightLevel l = fused->accuracy.by_weight.atCompleteness(other.accuracy.completeness);
        print_info("  mesh as complete as %s (%.1f %%, %.3f m): its vertices of weight >= %.0f, %.1f %%, %.3f m\n",
                   other.score.source.c_str(), 100 * other.accuracy.completeness, other.accuracy.accuracy_mean_m,
                   l.min_weight, 100 * l.completeness, l.accuracy_mean_m);
      }
  if (!e.no_ghosts.empty())
    print_info("  no ghost figure: %s\n", e.no_ghosts.c_str());
}

constexpr double kGhostDistanceM = 0.2; // farther than this from the static surface: not the road under a car

} // namespace

/// The memory budget against the run's predicted peak, before any frame is read: an explicit
/// budget (tsdf_volume.max_memory_mb, -max_memory > 0) refuses a run predicted to exceed it;
/// the default one (three quarters of RAM) warns, since the prediction is an upper bound that
/// grows with the space the cameras swept, not with the surface they saw. With estimated
/// poses nothing is known before the run: the volume's own check at each growth stays.
void checkMemoryBudget(const msf::Pipeline& pipeline, const msf::PoseList& poses, int maps, bool scores_every_frame,
                       double max_memory_mb, msf::RunReport& report) {
  const double budget_mb = static_cast<double>(pipeline.volume().maxMemoryBytes()) / (1024.0 * 1024.0);
  if (poses.empty()) {
    print_info("Memory: the poses are estimated as the run goes, so its peak is not predicted; the TSDF volume "
               "stops the run at the first frame whose blocks would exceed the budget (%.0f MiB)\n",
               budget_mb);
    return;
  }
  const msf::MemoryPrediction p = pipeline.predictMemory(poses, maps, scores_every_frame);
  report.predicted_memory_mb = p.total_mb;
  print_info("Memory: predicted peak %.0f MiB (%s), budget %.0f MiB%s (predicted in %.0f ms)\n", p.total_mb,
             p.describe().c_str(), budget_mb,
             max_memory_mb > 0 ? "" : " (three quarters of RAM)", p.ms);
  if (p.total_mb <= budget_mb)
    return;
  if (max_memory_mb > 0)
    throw msf::InvalidInputError(
        "the run is predicted to need up to " + std::to_string(static_cast<long long>(std::ceil(p.total_mb))) +
        " MiB at its peak (" + p.describe() + "), over the memory budget of " +
        std::to_string(static_cast<long long>(budget_mb)) +
        " MiB (tsdf_volume.max_memory_mb, -max_memory): use fewer frames, larger voxels, a streamed map (-stream R) "
        "or a larger budget");
  print_warn("the run is predicted to need up to %.0f MiB at its peak, over three quarters of RAM (%.0f MiB): the "
             "prediction is an upper bound; the run stops at the first frame whose blocks would not fit\n",
             p.total_mb, budget_mb);
}

int main(int argc, char** argv) {
  std::string out = "msf_out", frames_text = "0:", poses_option, config_path;
  int panels = 3;
  bool save_depth = false, holdout = false, compare_sources = false, compare_paper = false;
  msf::PipelineConfig config;
  msf::tool::CommandLine cli(
      "msf_reconstruct", "[DATASET_DIR] [options]",
      "Reconstructs a KITTI odometry sequence, a KITTI raw drive or a synthetic sequence (msf_synth) into a coloured "
      "mesh: LiDAR projection + compound interpolation and SGBM stereo, fused per pixel, integrated into a "
      "regularized TSDF, meshed by marching cubes. Without DATASET_DIR it generates the default synthetic street "
      "(20 frames) in a temporary folder and reconstructs it.");
  cli.value("-o", "DIR", out,
            "output folder (default {default}): mesh.ply, volume.pcd, summary.json, frames.csv, runtime.png, "
            "depth_NNNNNN.png, mesh_preview.png, report.md, config.yaml, poses.txt")
      .value("-config", "FILE", [&](const std::string& path) {
               config = msf::PipelineConfig::load(path);
               config_path = path;
             },
             "YAML configuration (config/kitti.yaml); the options below override it")
      .value("-frames", "a:b", frames_text, "frame range, inclusive (default: all)")
      .value("-poses", "P", poses_option,
             "dataset: the dataset's poses (the default when it has them) | estimate: LiDAR odometry as each frame is "
             "loaded (the default without them; section odometry) | a KITTI poses file, line i for frame i. "
             "OUT/poses.txt holds the poses used")
      .value("-voxel", "V", config.volume.voxel_size_m, "voxel size in metres (tsdf_volume.voxel_size_m)")
      .value("-lambda", "L", config.integrator.lambda, "regularization of eq. 7 (tsdf_integrator.lambda)")
      .value("-panels", "N", panels,
             "depth panels to draw, spread over the frames (default {default}, at most " + std::to_string(kMaxPanels) +
                 ")")
      .value("-stream", "R", config.streaming.active_radius_m,
             "keep only R metres around the camera in memory (streaming.active_radius_m; at least the integrator's "
             "reach + a tile, 101 m with the shipped configs): the rest is meshed into OUT/tiles/X_Y_Z.ply and its TSDF "
             "written to OUT/tsdf/ as it leaves; mesh.ply is their union (no volume.pcd, no mesh scores, no preview; "
             "msf_mesh -store OUT meshes the TSDF again). See docs/streaming.md")
      .value("-max_memory", "MB", config.volume.max_memory_mb,
             "memory budget of the run (tsdf_volume.max_memory_mb; 0: 3/4 of RAM): with the poses known before the "
            "run (the dataset's or a file's), a run whose predicted peak exceeds it is refused before it starts; "
            "the TSDF volume also stops the run at the first frame whose blocks would not fit")
      .flag("-save_depth", save_depth, "also write each frame's fused depth as OUT/depth/NNNNNN.pcd")
      .flag("-holdout", holdout,
            "evaluation protocol 4: the held-out rings (config section rings) are removed from every scan before the "
            "pipeline sees it and become the ground truth; the mesh, rendered at every frame's pose, is scored at "
            "them beside the fused depth")
      .flag("-compare_sources", compare_sources,
            "also integrate the interpolated LiDAR alone and SGBM alone into volumes of their own (mesh_lidar.ply, "
            "mesh_stereo.ply), scored as the mesh is")
      .flag("-compare_paper", compare_paper,
            "also run the paper as published (config/paper.yaml: docs/paper.md) on the same frames into a map of its "
            "own (mesh_paper.ply); its per-frame depth (paper) and mesh are scored beside ours")
      .note("With ground truth (-holdout, or a synthetic sequence's gt/), summary.json and report.md hold the "
            "protocol 4 rows: mesh, fused (and mesh_lidar, mesh_stereo, mesh_paper, paper), within the map's depth "
            "range and all.\n"
            "OUT/config.yaml is the configuration in full; -config OUT/config.yaml repeats the run.")
      .note("Ctrl-C (or SIGTERM) stops after the frames under way and still writes the mesh and the summary (exit "
            "code 130); a second one also skips the mesh's scores and renderings (summary.json lists them under "
            "\"skipped\"); later ones are ignored until the mesh and the summary are written.");
  return cli.run(argc, argv, 0, [&](const msf::tool::Arguments& positional) {
    if (positional.size() > 1) {
      std::string extra;
      for (std::size_t k = 1; k < positional.size(); ++k)
        extra += (k > 1 ? "', '" : "") + positional[k];
      std::string flags;
      for (const std::string& flag : cli.flags())
        flags += (flags.empty() ? "" : ", ") + flag;
      throw msf::InvalidInputError("expected at most one DATASET_DIR, got '" + positional.front() + "' and '" + extra +
                                   "' too (" + flags + " take no value; see -h)");
    }
    config.validate();
    if (panels < 0 || panels > kMaxPanels)
      throw msf::InvalidInputError("-panels must be 0.." + std::to_string(kMaxPanels) + ", not " + std::to_string(panels));
    const bool streaming = config.streaming.enabled();
    if (streaming && config.mesher.min_component_triangles > 0)
      std::printf("Note: a streamed map keeps its small pieces (marching_cubes.min_component_triangles is not "
                  "applied): its tiles are meshed apart, and a piece may cross them\n");
    if (streaming && (holdout || compare_sources || compare_paper))
      throw msf::InvalidInputError(std::string(holdout ? "-holdout" : compare_sources ? "-compare_sources" : "-compare_paper") +
                                   " needs the whole map in memory: not with a streamed map (-stream, " +
                                   "streaming.active_radius_m)");
    const msf::FrameRange range = msf::FrameRange::parse(frames_text);

    // Inputs inside OUT are refused: OUT is replaced as a whole.
    const std::string poses_file = poses_option == "dataset" || poses_option == "estimate" ? "" : poses_option;
    installStopHandler();
    msf::OutputFolder output(out, "msf_reconstruct",
                             {positional.empty() ? "" : positional.front(), config_path, poses_file});
    const std::string stage = output.dir(); // where this run writes; `out` at the end

    // The dataset, or the default synthetic street generated inside the staging folder (a
    // killed run's is removed with it by the next run) and removed before the commit.
    std::string dataset;
    const fs::path street = fs::path(stage) / ".street";
    if (positional.empty())
      dataset = generateDefaultStreet(street.string());
    else
      dataset = positional.front();
    const msf::Sequence sequence(dataset);
    const std::vector<std::size_t> frames = sequence.indices(range);
    msf::PoseSource poses(poses_option, sequence, frames, config.odometry);
    const msf::Calibration& calibration = sequence.calibration();
    if (!fs::is_directory(fs::path(sequence.imagePath(2, frames.front())).parent_path()))
      print_warn("'%s' has no colour camera (image_2): the mesh is coloured from the grey left image\n",
                 sequence.directory().c_str());
    const msf::HoldoutConfig holdout_config{config.rings, config.projection, {}};
    if (holdout) {
      // The first frame's split, before any work: a scan without rings is a clear error at once.
      msf::Frame first = sequence.load(frames.front(), false);
      holdOutRings(first, sequence, holdout_config);
    }
    if (save_depth)
      fs::create_directories(fs::path(stage) / "depth");

    msf::RunReport report;
    report.dataset = sequence.directory();
    report.layout = !sequence.groundTruthDir().empty()            ? "synthetic"
                    : sequence.layout() == msf::Sequence::Layout::Raw ? "raw"
                                                                    : "odometry";
    report.frames_requested = frames.size();
    report.voxel_size_m = config.volume.voxel_size_m;
    report.lambda = config.integrator.lambda;
    std::ostringstream config_yaml;
    config.print(config_yaml);
    report.config_yaml = config_yaml.str();
    report.config_file = "config.yaml";
    report.trajectory = poses.description();

    GroundTruthScores scores;
    scores.keep_surface = !streaming;
    if (!sequence.groundTruthDir().empty()) {
      scores.truth = std::make_unique<msf::synthetic::GroundTruth>(sequence.groundTruthDir());
      // The true surface and what each of its vertices is (ground, building, tree...: the mesh
      // scores split by it; datasets written before gt/scene_classes.txt have none), read
      // before the run: a garbled file stops it now, not after its last frame.
      if (scores.keep_surface) {
        msf::loadMesh(scores.truth->sceneMeshPath(), scores.scene);
        if (scores.truth->hasSceneClasses())
          scores.classes =
              scores.truth->sceneClasses(static_cast<std::size_t>(scores.scene.cloud.width) * scores.scene.cloud.height);
      }
    }

    // Protocol 4: the held-out rings with -holdout, else a synthetic sequence's exact depth.
    std::unique_ptr<msf::ReconstructionEvaluation> evaluation;
    // Protocol 4 renders the whole mesh at every frame's pose: not for a streamed map, whose
    // mesh is on disk (its depth scores are bounded and kept).
    if (!streaming && (holdout || scores.truth))
      evaluation = std::make_unique<msf::ReconstructionEvaluation>(msf::PinholeCamera::fromCalibration(calibration, 0),
                                                                   calibration.focalBaseline(),
                                                                   config.integrator.max_depth_m, holdout_config.d1);
    const bool moving_split = !holdout && scores.truth && scores.truth->hasMovingMasks();
    std::vector<std::unique_ptr<SourceMap>> source_maps;
    if (compare_sources)
      for (const msf::DepthSource source : {msf::DepthSource::Lidar, msf::DepthSource::Stereo})
        source_maps.push_back(std::make_unique<SourceMap>(source, config));
    std::unique_ptr<PaperRun> paper;
    if (compare_paper)
      paper = std::make_unique<PaperRun>(calibration, config);

    // Before any frame is read: a run predicted over an explicit budget does not start.
    msf::Pipeline pipeline(calibration, config);
    checkMemoryBudget(pipeline, poses.knownPoses(frames), 1 + (compare_sources ? 2 : 0) + (compare_paper ? 1 : 0),
                      evaluation != nullptr, config.volume.max_memory_mb, report);

    print_highlight("Reconstructing ");
    print_value("%zu", frames.size());
    print_info(" frames of ");
    print_value("%s", sequence.directory().c_str());
    print_info(" into ");
    print_value("%s", out.c_str());
    print_info("%s%s; poses: %s\n", holdout ? ", held-out rings removed from every scan" : "",
               compare_sources ? ", with a map of each source alone" : "", poses.description().c_str());

    if (streaming)
      pipeline.setStreamingDirectory(stage);
    const std::set<std::size_t> panel_frames = spread(frames, panels);
    pipeline.setKeepSparse(!panel_frames.empty()); // the panels show the projected scan
    PendingTruth heldout_truth;
    pipeline.setFrameFilter([&](msf::Frame& frame) {
      if (holdout)
        heldout_truth.put(frame.index, holdOutRings(frame, sequence, holdout_config));
      poses.apply(frame);
    });
    if (poses.kind() == msf::PoseSource::Kind::Estimated) // after the hold-out: the scan the pipeline sees
      pipeline.setPoseEstimator([&](const msf::Frame& frame) { return poses.estimate(frame); });
    msf::PoseList used_poses;
    Progress progress(frames.size());

    const auto stats = pipeline.run(
        sequence, frames,
        [&](msf::FrameResult& r) {
          report.frames.push_back({r.index, r.name, r.times,
                                   r.times.load_ms + r.times.depth_ms + r.times.fusion_ms + r.times.integrate_ms,
                                   msf::residentMemoryMb()});
          used_poses.push_back(r.T_world_cam0);
          cv::Mat synthetic_depth;
          if (scores.truth) {
            synthetic_depth = scores.truth->depth(scores.truth->indexOf(r.name));
            scores.add(r, synthetic_depth, calibration, config.integrator.max_depth_m);
          }
          if (evaluation) {
            if (holdout)
              evaluation->addGroundTruth(r.index, r.T_world_cam0, heldout_truth.take(r.index));
            else
              evaluation->addGroundTruth(r.index, r.T_world_cam0, synthetic_depth,
                                         moving_split ? scores.truth->movingMask(scores.truth->indexOf(r.name))
                                                      : cv::Mat());
            evaluation->scoreDepth("fused", r.index, r.fused.depth);
          }
          if (paper) {
            // On this thread, after ours: the paper's run does not share the stages' threads.
            msf::Frame again = sequence.load(r.index);
            if (holdout)
              holdOutRings(again, sequence, holdout_config);
            again.T_world_cam0 = r.T_world_cam0;
            again.has_pose = true;
            msf::FrameResult p = paper->pipeline.computeDepth(again);
            paper->pipeline.integrate(p);
            if (scores.truth)
              scores.addDepth("paper", r.name, synthetic_depth, p.fused.depth, calibration.focalBaseline());
            if (evaluation)
              evaluation->scoreDepth("paper", r.index, p.fused.depth);
          }
          for (auto& map : source_maps) {
            const msf::DepthFrame frame = msf::sourceDepthFrame(r, map->source, config.fusion, calibration.focalBaseline());
            map->integrator.integrate(frame, r.T_world_cam0);
            if (map->source == msf::DepthSource::Lidar) // the LiDAR's own free space; SGBM alone has none
              msf::carveWithScan(map->integrator, r, frame.camera, config.fusion, calibration);
          }
          if (save_depth)
            msf::saveCloud((fs::path(stage) / "depth" / (r.name + ".pcd")).string(), fusedCloud(r.fused, calibration));
          if (panel_frames.count(r.index)) {
            const cv::Mat& fused = r.fused.depth;
            msf::DepthPanel panel;
            panel.addImage("left image (camera 0), frame " + r.name, r.left);
            if (!r.lidar_sparse.empty())
              panel.addDepth(holdout ? "projected LiDAR (input rings)" : "projected LiDAR", r.lidar_sparse, 3.f, 60.f, 1);
            panel.addDepth("interpolated LiDAR", r.lidar_depth, 3.f, 60.f);
            panel.addDepth("SGBM", r.stereo_depth, 3.f, 60.f);
            panel.addDepth("fused", fused, 3.f, 60.f);
            if (scores.truth)
              panel.addError("|fused - ground truth|", fused, synthetic_depth, 2.f);
            const std::string name = "depth_" + r.name + ".png";
            msf::writeImage((fs::path(stage) / name).string(), panel.render());
            report.depth_panels.push_back(name);
          }
          progress.frame(r, report.frames.size());
        },
        &msf::tool::stopFlag());
    progress.end();
    report.wall_s = stats.wall_s;
    report.first_frame_s = stats.first_frame_s;
    report.interrupted = stats.interrupted;
    if (stats.interrupted)
      print_warn("Interrupted after %zu of %zu frames: writing what was integrated.\n", stats.frames_done, frames.size());

    TicToc tt;
    tt.tic();
    print_highlight(streaming ? "Meshing the tiles in memory, writing the union " : "Meshing ");
    // A streamed map's mesh is on disk (the union of OUT/tiles in OUT/mesh.ply), not in memory.
    report.observed_voxels = pipeline.volume().numObservedVoxels();
    report.blocks = pipeline.volume().numBlocks();
    report.volume_memory_mb = static_cast<double>(pipeline.volume().memoryBytes()) / (1024.0 * 1024.0);
    msf::TriangleMesh streamed;
    const std::size_t streamed_triangles =
        streaming ? pipeline.finishStreaming((fs::path(stage) / report.mesh_file).string()) : 0;
    const msf::TriangleMesh& mesh = streaming ? streamed : pipeline.updateMesh();
    report.mesh_ms = tt.toc();
    msf::tool::printDone(report.mesh_ms, streaming ? streamed_triangles : mesh.triangles.size());
    report.vertices = mesh.vertices.size();
    report.triangles = streaming ? streamed_triangles : mesh.triangles.size();
    report.pieces_removed = pipeline.meshStats().components_removed;
    report.triangles_removed = pipeline.meshStats().triangles_removed;
    if (streaming) {
      const msf::StreamingMap::Stats& st = pipeline.streaming()->stats();
      print_info("Streamed: %zu tiles written, %zu read back (%zu on allocation), %zu meshed again; %zu blocks freed; "
                 "%.0f ms in all\n",
                 st.tiles_written, st.tiles_reloaded, st.tiles_reloaded_on_allocation, st.tiles_remeshed,
                 st.blocks_freed, st.stream_ms);
    }
    const msf::TriangleMesh* paper_mesh = nullptr;
    if (paper) {
      tt.tic();
      print_highlight("Meshing the paper's map ");
      paper_mesh = &paper->pipeline.updateMesh();
      msf::tool::printDone(tt.toc(), paper_mesh->triangles.size());
    }
    if (!source_maps.empty() && hurried()) {
      // Stopped twice: the single-source maps are not meshed (their volumes are lost).
      report.skipped.push_back("compare_sources");
      source_maps.clear();
    }
    for (auto& map : source_maps) {
      tt.tic();
      print_highlight("Meshing the %s map ", msf::toString(map->source));
      msf::MarchingCubes(config.mesher).extract(map->volume, map->mesh);
      msf::tool::printDone(tt.toc(), map->mesh.triangles.size());
    }

    tt.tic();
    print_highlight("Saving ");
    print_value("%s/{%s%s} ", out.c_str(), streaming ? "config.yaml (mesh.ply, tiles/, tsdf/ are written)" : "mesh.ply, volume.pcd",
                compare_sources ? ", mesh_lidar.ply, mesh_stereo.ply" : "");
    pcl::PolygonMesh polygon_mesh;
    mesh.toPolygonMesh(polygon_mesh);
    if (streaming) {
      if (streamed_triangles == 0)
        print_warn("\nno surface was reconstructed: mesh.ply is not written\n");
    } else if (!mesh.triangles.empty()) {
      msf::saveMesh((fs::path(stage) / report.mesh_file).string(), polygon_mesh);
      pipeline.volume().save((fs::path(stage) / report.volume_file).string());
    } else {
      print_warn("\nno surface was reconstructed: mesh.ply and volume.pcd are not written\n");
    }
    std::map<std::string, pcl::PolygonMesh> source_polygons;
    for (const auto& map : source_maps)
      if (!map->mesh.triangles.empty()) {
        map->mesh.toPolygonMesh(source_polygons[map->name()]);
        msf::saveMesh((fs::path(stage) / (map->name() + ".ply")).string(), source_polygons[map->name()]);
      }
    if (paper_mesh && !paper_mesh->triangles.empty()) {
      paper_mesh->toPolygonMesh(source_polygons["mesh_paper"]);
      msf::saveMesh((fs::path(stage) / "mesh_paper.ply").string(), source_polygons["mesh_paper"]);
    }
    msf::writeAtomically((fs::path(stage) / report.config_file).string(), [&](const std::string& tmp) {
      std::ofstream file(tmp);
      file << report.config_yaml;
      if (!file)
        throw msf::IOError("cannot write '" + tmp + "'");
    });
    msf::tool::printDone(tt.toc(), mesh.vertices.size());

    if (!mesh.triangles.empty() && hurried()) {
      report.skipped.push_back("mesh_preview");
    } else if (!mesh.triangles.empty()) {
      // Preview: from above, and from the first frame's camera.
      const cv::Size size = calibration.requireImageSize();
      const Eigen::Isometry3d first_pose = used_poses.front();
      cv::Mat above = msf::MeshRenderer::renderFromAbove(mesh, -(first_pose.linear().col(1)),
                                                         cv::Size(size.width, size.width / 2));
      cv::Mat camera = msf::MeshRenderer::render(mesh, first_pose, calibration.fx(), calibration.fy(),
                                                 calibration.cx(), calibration.cy(), size);
      cv::Mat preview;
      cv::vconcat(above, camera, preview);
      report.preview_file = "mesh_preview.png";
      msf::writeImage((fs::path(stage) / report.preview_file).string(), preview);
    }

    // The meshes against the true surface (synthetic), each as the fused one.
    std::map<std::string, std::pair<const msf::TriangleMesh*, const pcl::PolygonMesh*>> meshes;
    if (!streaming)
      meshes["mesh"] = {&mesh, &polygon_mesh};
    for (const auto& map : source_maps)
      meshes[map->name()] = {&map->mesh, source_polygons.count(map->name()) ? &source_polygons[map->name()] : nullptr};
    if (paper_mesh)
      meshes["mesh_paper"] = {paper_mesh, source_polygons.count("mesh_paper") ? &source_polygons["mesh_paper"] : nullptr};
    std::map<std::string, msf::MeshAccuracy> accuracy;
    std::map<std::string, msf::GhostMetrics> ghosts;
    if (scores.truth) {
      for (const auto& [name, acc] : scores.all) {
        auto& d = report.depth[name];
        d.all = acc.metrics();
        d.background = scores.background[name].metrics();
        d.foreground = scores.foreground[name].metrics();
        d.has_split = true;
      }
    }
    if (scores.truth && hurried()) {
      report.skipped.push_back("mesh_accuracy");
    } else if (scores.truth) {
      const std::string scene = scores.truth->sceneMeshPath();
      tt.tic();
      print_highlight("Scoring the mesh%s against ", meshes.size() > 1 ? "es" : "");
      print_value("%s ", scene.c_str());
      if (scores.scene.polygons.empty())
        msf::loadMesh(scene, scores.scene);
      const pcl::PolygonMesh& truth = scores.scene;
      const std::optional<msf::SurfaceClasses>& classes = scores.classes;
      // Where moving objects were: inside a box of gt/moving_objects.txt at any frame, grown by
      // a voxel (a car's surface is meshed up to a voxel off its box).
      msf::MovingSpace was_moving;
      if (fs::exists(scores.truth->movingBoxesPath())) {
        const double margin = config.volume.voxel_size_m;
        was_moving = [boxes = scores.truth->movingBoxes(), margin](const Eigen::Vector3f& p) {
          const Eigen::Vector3d q = p.cast<double>();
          for (const auto& box : boxes)
            if (box.contains(q, margin))
              return true;
          return false;
        };
      }
      std::unique_ptr<msf::SurfaceDistance> static_surface;
      if (was_moving)
        static_surface = std::make_unique<msf::SurfaceDistance>(truth); // gt/scene.ply: the static scene
      // The nearest distance each piece of the seen surface was seen from (cells of a voxel):
      // what a frame far away cannot place within the completeness threshold.
      const std::vector<float> view_distance = msf::nearestViewDistance(
          scores.seen_surface, scores.seen_depth, static_cast<float>(config.volume.voxel_size_m));
      for (const auto& [name, m] : meshes) {
        if (!m.second)
          continue;
        // Marching cubes' meshes weigh their vertices: also scored as the bar on them rises.
        const std::vector<float>& weights = m.first->weights;
        accuracy[name] =
            msf::evaluateMesh(*m.second, truth, scores.seen_surface, 2.0 * config.volume.voxel_size_m, 1.0, 200000,
                              &view_distance, weights.size() == m.first->vertices.size() ? &weights : nullptr,
                              classes ? &*classes : nullptr);
        if (was_moving)
          ghosts[name] = msf::measureGhosts(m.first->vertices, *static_surface, was_moving, kGhostDistanceM);
      }
      if (accuracy.count("mesh")) {
        report.mesh_accuracy = accuracy["mesh"];
        report.has_mesh_accuracy = true;
      }
      msf::tool::printDone(tt.toc(), accuracy.size());
    }

    if (evaluation && hurried()) {
      report.skipped.push_back("reconstruction_evaluation");
    } else if (evaluation) {
      tt.tic();
      print_highlight("Rendering the mesh%s at every frame's pose ", meshes.size() > 1 ? "es" : "");
      for (const auto& [name, m] : meshes)
        evaluation->scoreMesh(name, *m.first);
      msf::tool::printDone(tt.toc(), evaluation->frames() * meshes.size());
      msf::RunReport::MapEvaluation& e = report.map_evaluation;
      e.truth = holdout ? "held-out rings (ring id % " + std::to_string(config.rings.modulo) +
                              " == " + std::to_string(config.rings.heldout_remainder) + ") projected into camera 0"
                        : "the synthetic sequence's exact depth (gt/depth_0)";
      e.range_m = config.integrator.max_depth_m;
      e.frames = evaluation->frames();
      e.gt_pixels = evaluation->groundTruthPixels();
      e.moving_split = moving_split;
      if (ghosts.empty())
        e.no_ghosts = noGhostsReason(scores.truth.get());
      const auto rows = evaluation->scores();
      for (const char* source : {"mesh", "fused", "mesh_lidar", "mesh_stereo", "mesh_paper", "paper"})
        for (const auto& score : rows)
          if (score.source == source) {
            msf::RunReport::MapEvaluation::Row row;
            row.score = score;
            row.has_accuracy = accuracy.count(source) > 0;
            if (row.has_accuracy)
              row.accuracy = accuracy[source];
            row.has_ghosts = ghosts.count(source) > 0;
            if (row.has_ghosts)
              row.ghosts = ghosts[source];
            e.rows.push_back(row);
          }
    }

    report.pose_ms = poses.estimateMs();
    if (!used_poses.empty()) {
      msf::saveOdometryPoses((fs::path(stage) / report.poses_file).string(), used_poses);
      // Short names: the legend beside the plot is narrow.
      const char* used_name = poses.kind() == msf::PoseSource::Kind::Estimated ? "estimated"
                              : poses.kind() == msf::PoseSource::Kind::File    ? "poses file"
                                                                                : "dataset";
      std::vector<std::pair<std::string, msf::PoseList>> trajectories{{used_name, used_poses}};
      if (sequence.hasPoses() && poses.kind() != msf::PoseSource::Kind::Dataset) {
        msf::PoseList reference;
        for (const auto& f : report.frames)
          reference.push_back(sequence.poses()[f.index]);
        trajectories.emplace_back("dataset", reference);
        if (used_poses.size() > 1) {
          report.trajectory_metrics = msf::evaluateOdometry(used_poses, reference);
          report.has_trajectory_metrics = report.trajectory_metrics.path_length_m > 0.0;
          report.trajectory_reference = sequence.posesName();
        }
      }
      report.trajectory_plot_file = "trajectory.png";
      msf::writeImage((fs::path(stage) / report.trajectory_plot_file).string(),
                      msf::plotTrajectoriesFromAbove(trajectories));
    }
    report.peak_memory_mb = msf::peakMemoryMb();
    report.writeFramesCsv((fs::path(stage) / "frames.csv").string());
    if (!report.frames.empty())
      report.writeRuntimePlot((fs::path(stage) / "runtime.png").string());
    report.writeSummaryJson((fs::path(stage) / "summary.json").string());
    report.writeMarkdown((fs::path(stage) / "report.md").string());
    if (report.triangles == 0 && !stats.interrupted)
      throw msf::InvalidInputError("no surface was reconstructed from " + std::to_string(report.frames.size()) +
                                   " frames: nothing is written to '" + out + "'");
    std::error_code ec;
    fs::remove_all(street, ec);
    output.commit();

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
    if (!report.map_evaluation.rows.empty())
      printMapEvaluation(report.map_evaluation);
    print_info("Report: ");
    print_value("%s/report.md\n", out.c_str());
    return stats.interrupted ? 130 : 0;
  });
}
