// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The main job: a dataset (or the built-in synthetic street) to a coloured mesh, with a report
// of speed and, where ground truth exists, accuracy. A door over the library's engine
// (msf::Reconstructor): a reader feeds it, writers and evaluations take what it gives.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/datasets/open_dataset.h>
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/sequence.h>
#include <msf/io/world_frame.h>
#include <msf/pipeline/frame_panel.h>
#include <msf/pipeline/fused_cloud.h>
#include <msf/pipeline/pose_source.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/ring_holdout.h>
#include <msf/pipeline/run_outputs.h>
#include <msf/pipeline/rig_agreement.h>
#include <msf/pipeline/run_report.h>
#include <msf/pipeline/sky_scoring.h>
#include <msf/pipeline/source_maps.h>
#include <msf/pipeline/synthetic_scoring.h>
#include <msf/synthetic/synthetic_generator.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

constexpr int kMaxPanels = 100;

/// What the command line asks for beyond the configuration.
struct Request {
  std::string out = "msf_out", frames = "0:", poses, config_path, dataset, world = "camera";
  msf::DatasetOptions reader;
  int panels = 3;
  bool save_depth = false, holdout = false, compare_sources = false, compare_paper = false;
};

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

class Progress {
public:
  explicit Progress(std::size_t total) : total_(total), tty_(::isatty(STDOUT_FILENO)), start_(Clock::now()) {}
  void frame(const msf::FrameResult& r, std::size_t done) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const double fps = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    const double left = fps > 0 ? static_cast<double>(total_ - done) / fps : 0.0;
    if (tty_)
      std::printf("\r  frame %zu/%zu  %.1f fps  %.0f s left   %s", done, total_, fps, left, done == total_ ? "\n" : "");
    else
      std::printf("  frame %s (%zu/%zu): depth %.1f ms, fusion %.1f ms, integrate %.1f ms, %.1f fps\n",
                  r.name.c_str(), done, total_, r.times.depth_ms, r.times.fusion_ms, r.times.integrate_ms, fps);
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
  for (int k = 0; !frames.empty() && k < count; ++k)
    chosen.insert(frames[count == 1 ? 0 : (frames.size() - 1) * k / (count - 1)]);
  return chosen;
}

std::string generateDefaultStreet(const std::string& dir) {
  msf::synthetic::SyntheticConfig config;
  config.frames = 20;
  print_highlight("No dataset given: generating the default synthetic street (%d frames) in ", config.frames);
  print_value("%s\n", dir.c_str());
  TicToc tt;
  tt.tic();
  msf::synthetic::SyntheticGenerator(config).writeDataset(dir, [](std::size_t, double, std::size_t) {
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
      print_info(", ghosts %.2f %%, crumbs %zu", 100 * r.ghosts.share, r.crumbs.crumbs);
    if (r.has_seen_through)
      print_info(", small pieces seen through %zu", r.seen_through.seen_through);
    print_info("\n");
  }
  if (e.transient_split)
    for (const auto& r : e.rows) {
      const msf::DepthMetrics &a = r.score.lasting_within_range, &b = r.score.transient_within_range;
      print_info("  %-12s within range, lasting %.4f / %.2f%% (%zu px), transient %.4f / %.2f%% (%zu px)\n",
                 r.score.source.c_str(), a.coverage, 100 * a.d1_all, a.gt_pixels, b.coverage, 100 * b.d1_all,
                 b.gt_pixels);
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

/// The console's protocol 6 lines: the open sky each mesh covers, by the image's sky mask and,
/// on a synthetic sequence, by its true sky (where the mask also takes bright blank façades).
void printOpenSky(const std::map<std::string, msf::SkyCoverage>& open_sky, const msf::RunReport::MapEvaluation& e) {
  for (const auto& [name, c] : open_sky) {
    char depth[64] = ", no surface over it";
    if (c.covered_pixels > 0)
      std::snprintf(depth, sizeof depth, ", at a median depth of %.1f m", c.covered_depth_median_m);
    print_info("  open sky covered by %-11s %.2f %% of %zu pixels in %zu frames (mean per frame %.2f %%, worst "
               "%.2f %% at frame %zu)%s\n",
               name.c_str(), 100 * c.share, c.sky_pixels, c.frames, 100 * c.mean_frame_share, 100 * c.worst_share,
               c.worst_frame, depth);
  }
  for (const auto& r : e.rows)
    if (r.true_sky.sky_pixels > 0)
      print_info("  true sky covered by %-11s %.2f %% of %zu pixels (worst %.2f %% at frame %zu), by sheets off the "
                 "true surface %.2f %% (the image's mask above can also take bright blank façades for sky)\n",
                 r.score.source.c_str(), 100 * r.true_sky.share, r.true_sky.sky_pixels, 100 * r.true_sky.worst_share,
                 r.true_sky.worst_frame, 100 * r.true_sky_sheets.share);
}

void printSummary(const msf::RunReport& report, const std::string& out) {
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
  printOpenSky(report.open_sky, report.map_evaluation);
  print_info("Report: ");
  print_value("%s/report.md\n", out.c_str());
}

/// One run of msf_reconstruct: the engine over the source's frames, with the evaluations the
/// request and the dataset call for, written into the output folder's staging directory.
class Run {
public:
  Run(const Request& request, const msf::PipelineConfig& config, const msf::FrameSource& source,
      const std::string& stage)
      : request_(request), config_(config), source_(source), stage_(stage),
        frames_(source.indices(msf::FrameRange::parse(request.frames))),
        poses_(request.poses, source, frames_),
        holdout_(source, msf::HoldoutConfig{config.rings, config.projection, {}}),
        panel_frames_(spread(frames_, request.panels)),
        T_out_world_(msf::outputTransform(msf::parseWorldFrame(request.world), firstPose())),
        on_rig_(msf::adaptToRig(config, source.calibration())) {
    if (!source.hasColor())
      print_warn("'%s' has no colour camera (a KITTI folder's image_2, a folder's color/, a bag's -color_topic): "
                 "the mesh is coloured from the grey left image\n",
                 source.description().c_str());
    if (msf::parseWorldFrame(request.world) == msf::WorldFrame::ZUp && msf::worldIsZUp(firstPose()))
      print_info("The poses' world is already z-up (%s): -world z_up leaves it as it is\n",
                 poses_.description().c_str());
    if (request.holdout) { // the first frame's split, before any work: a scan without rings is a clear error at once
      msf::Frame first = source.load(frames_.front(), false);
      holdout_.split(first);
      holdout_.take(first.index);
    }
    engine_ = makeEngine();
    planMemory();
    describeReport();
    makeEvaluations();
  }

  /// The frames through the engine; returns whether the run was interrupted.
  bool reconstruct() {
    print_highlight("Reconstructing ");
    print_value("%zu", frames_.size());
    print_info(" frames of ");
    print_value("%s", source_.description().c_str());
    print_info(" into ");
    print_value("%s", request_.out.c_str());
    print_info("%s%s; poses: %s\n", request_.holdout ? ", held-out rings removed from every scan" : "",
               request_.compare_sources ? ", with a map of each source alone" : "", poses_.description().c_str());
    engine_->setFrameFilter([this](msf::Frame& frame) {
      if (sky_)
        sky_->addFrame(frame); // from the whole scan
      if (request_.holdout)
        holdout_.split(frame);
      if (truth_)
        truth_->addScan(frame); // the scan the map is made of
      poses_.apply(frame);
    });
    Progress progress(frames_.size());
    const auto stats = engine_->run(
        source_, frames_,
        [&](msf::FrameResult& r) {
          onFrame(r);
          progress.frame(r, report_.frames.size());
        },
        &msf::tool::stopFlag());
    progress.end();
    report_.wall_s = stats.wall_s;
    report_.first_frame_s = stats.first_frame_s;
    report_.interrupted = stats.interrupted;
    if (stats.interrupted)
      print_warn("Interrupted after %zu of %zu frames: writing what was integrated.\n", stats.frames_done,
                 frames_.size());
    const std::string rig_warning = msf::rigDisagreementWarning(report_.lidarStereoDisagreements());
    if (!rig_warning.empty())
      print_warn("Warning: %s\n", rig_warning.c_str());
    return stats.interrupted;
  }

  /// The meshes, their files, the scores and the report, all into the staging directory.
  /// Throws InvalidInputError when no surface was reconstructed from a whole run.
  void finish(bool interrupted) {
    meshMaps();
    saveMeshes();
    scoreMeshes();
    report_.pose_ms = engine_->odometryMs();
    const char* used_name = poses_.kind() == msf::PoseSource::Kind::Estimated ? "estimated"
                            : poses_.kind() == msf::PoseSource::Kind::File    ? "poses file"
                            : poses_.kind() == msf::PoseSource::Kind::Refined ? "refined"
                                                                              : "dataset";
    msf::writeTrajectory(stage_, used_poses_, frames_, used_name, source_, T_out_world_, report_);
    report_.peak_memory_mb = msf::peakMemoryMb();
    report_.writeFramesCsv(path("frames.csv"));
    if (!report_.frames.empty())
      report_.writeRuntimePlot(path("runtime.png"));
    report_.writeSummaryJson(path("summary.json"));
    report_.writeMarkdown(path("report.md"));
    if (report_.triangles == 0 && !interrupted)
      throw msf::InvalidInputError("no surface was reconstructed from " + std::to_string(report_.frames.size()) +
                                   " frames: nothing is written to '" + request_.out + "'");
  }

  const msf::RunReport& report() const { return report_; }

private:
  bool streaming() const { return config_.streaming.enabled(); }
  /// The first frame's pose when known before the run (the identity for the odometry's).
  Eigen::Isometry3d firstPose() const {
    const msf::PoseList known = poses_.knownPoses({frames_.front()});
    return known.empty() ? Eigen::Isometry3d::Identity() : known.front();
  }
  /// Whether the run may stream its map: every evaluation it was asked for works on a streamed one.
  bool mayStream() const {
    return !streaming() && !request_.holdout && !request_.compare_sources && !request_.compare_paper;
  }
  /// The pixels of each frame whose ground truth the run keeps to score the whole mesh at the end
  /// (makeEvaluations): a synthetic drive's every pixel; under -holdout the held-out rings' returns,
  /// a ring in rings.modulo of the scan's (those in the camera's view are fewer still).
  double scoredPixelsPerFrame(const msf::MemoryEvidence& evidence) const {
    if (streaming())
      return 0.0;
    if (!source_.groundTruthDir().empty())
      return static_cast<double>(source_.calibration().requireImageSize().area());
    return request_.holdout ? static_cast<double>(evidence.most_scan_returns) / config_.rings.modulo : 0.0;
  }
  int maps() const { return 1 + (request_.compare_sources ? 2 : 0) + (request_.compare_paper ? 1 : 0); }

  std::unique_ptr<msf::Reconstructor> makeEngine() const {
    msf::Reconstructor::Options options;
    options.poses = poses_.mode();
    options.stream_directory = streaming() ? stage_ : "";
    options.keep_sparse = !panel_frames_.empty(); // the panels show the projected scan
    return std::make_unique<msf::Reconstructor>(source_.calibration(), config_, options);
  }

  /// The memory budget against the run's predicted peak, before the run: a run over it whose
  /// evaluations allow it streams its map (streamOnItsOwn); otherwise an explicit budget
  /// (tsdf_volume.max_memory_mb > 0) refuses it, the default one (three quarters of RAM) warns.
  /// With estimated poses nothing is known before the run: the volume's own check at each
  /// growth stays.
  void planMemory() {
    const double budget_mb = static_cast<double>(engine_->volume().maxMemoryBytes()) / (1024.0 * 1024.0);
    const msf::PoseList poses = poses_.knownPoses(frames_);
    if (poses.empty()) {
      print_info("Memory: the poses are estimated as the run goes, so its peak is not predicted; the TSDF volume "
                 "stops the run at the first frame whose blocks would exceed the budget (%.0f MiB)\n",
                 budget_mb);
      return;
    }
    const msf::MemoryEvidence evidence = engine_->measureMemory(source_, frames_, poses);
    const msf::MemoryPrediction p = engine_->predictMemory(evidence, maps(), scoredPixelsPerFrame(evidence));
    report_.predicted_memory_mb = p.total_mb;
    print_info("Memory: predicted peak %.0f MiB (%s), budget %.0f MiB%s (predicted in %.0f ms)\n", p.total_mb,
               p.describe().c_str(), budget_mb, explicitBudget() ? "" : " (three quarters of RAM)", p.ms);
    if (p.total_mb <= budget_mb)
      return;
    if (mayStream())
      return streamOnItsOwn(p, evidence, budget_mb);
    const std::string whole = streaming() ? "" : ", and the run needs the whole map in memory (" + wholeMapReason() + ")";
    if (explicitBudget())
      throw msf::InvalidInputError("the run is predicted to need up to " + mib(p.total_mb) + " MiB at its peak (" +
                                   p.describe() + "), over the memory budget of " + mib(budget_mb, false) +
                                   " MiB (tsdf_volume.max_memory_mb, -max_memory)" + whole +
                                   ": use fewer frames, larger voxels, " +
                                   (streaming() ? "a smaller active radius" : "a streamed map (-stream R)") +
                                   " or a larger budget");
    print_warn("the run is predicted to need up to %.0f MiB at its peak, over three quarters of RAM (%.0f MiB)%s: "
               "the run stops at the first frame whose blocks would not fit\n",
               p.total_mb, budget_mb, whole.c_str());
  }

  /// A run predicted over the budget streams its map with the least active radius the
  /// integrator allows (its reach plus a tile: every block a frame changes stays in memory,
  /// and no more); an explicit budget that even the streamed run would exceed refuses it. The
  /// in-memory prediction's evidence serves: the streamed engine differs in its window only.
  void streamOnItsOwn(const msf::MemoryPrediction& in_memory, const msf::MemoryEvidence& evidence, double budget_mb) {
    const double radius = std::ceil(engine_->minimumStreamingRadius());
    config_.streaming.active_radius_m = radius;
    engine_ = makeEngine();
    const msf::MemoryPrediction p = engine_->predictMemory(evidence, maps(), scoredPixelsPerFrame(evidence));
    report_.predicted_memory_mb = p.total_mb;
    if (explicitBudget() && p.total_mb > budget_mb)
      throw msf::InvalidInputError(
          "the run is predicted to need up to " + mib(in_memory.total_mb) + " MiB at its peak in memory and " +
          mib(p.total_mb) + " MiB streamed with an active radius of " + mib(radius, false) + " m (" + p.describe() +
          "), over the memory budget of " + mib(budget_mb, false) +
          " MiB (tsdf_volume.max_memory_mb, -max_memory): use fewer frames, larger voxels or a larger budget");
    print_info("Memory: predicted %.0f MiB in memory, over the budget of %.0f MiB%s: streaming the map with an "
               "active radius of %.0f m (tiles in %s/tiles); predicted peak streamed %.0f MiB (%s)\n",
               in_memory.total_mb, budget_mb, explicitBudget() ? "" : " (three quarters of RAM)", radius,
               request_.out.c_str(), p.total_mb, p.describe().c_str());
    if (p.total_mb > budget_mb)
      print_warn("even streamed, the run is predicted over three quarters of RAM (%.0f MiB): the run stops at the "
                 "first frame whose blocks would not fit\n",
                 budget_mb);
  }

  bool explicitBudget() const { return config_.volume.max_memory_mb > 0; }
  std::string wholeMapReason() const {
    return request_.holdout ? "-holdout" : request_.compare_sources ? "-compare_sources" : "-compare_paper";
  }
  /// A figure in MiB for a message, rounded up (a prediction) or down (a budget).
  static std::string mib(double mb, bool up = true) {
    return std::to_string(static_cast<long long>(up ? std::ceil(mb) : std::floor(mb)));
  }
  std::string path(const std::string& name) const { return (fs::path(stage_) / name).string(); }

  void describeReport() {
    report_.dataset = source_.description();
    const auto* sequence = dynamic_cast<const msf::Sequence*>(&source_);
    report_.layout = !source_.groundTruthDir().empty()                                   ? "synthetic"
                     : sequence && sequence->layout() == msf::Sequence::Layout::Raw ? "raw"
                     : sequence                                                     ? "odometry"
                     : msf::isRosBag(source_.description())                         ? "ros bag"
                                                                                    : "generic";
    report_.frames_requested = frames_.size();
    report_.voxel_size_m = config_.volume.voxel_size_m;
    report_.lambda = config_.integrator.lambda;
    std::ostringstream config_yaml;
    config_.print(config_yaml);
    report_.config_yaml = config_yaml.str();
    report_.config_file = "config.yaml";
    report_.trajectory = poses_.description();
  }

  void makeEvaluations() {
    if (!source_.groundTruthDir().empty())
      truth_ = std::make_unique<msf::SyntheticScoring>(source_.groundTruthDir(), !streaming(),
                                                       config_.volume.voxel_size_m);
    // Protocol 4 renders the whole mesh at every frame's pose: not for a streamed map, whose
    // mesh is on disk (its depth scores are bounded and kept).
    if (!streaming() && (request_.holdout || truth_))
      evaluation_ = std::make_unique<msf::ReconstructionEvaluation>(
          msf::PinholeCamera::fromCalibration(source_.calibration(), 0), source_.calibration().focalBaseline(),
          on_rig_.integrator.max_depth_m, holdout_.config().d1);
    moving_split_ = truth_ && truth_->truth().hasMovingMasks();
    // Protocol 6 renders the whole mesh too.
    if (!streaming())
      sky_ = std::make_unique<msf::SkyScoring>(source_.calibration(), config_.projection, panel_frames_);
    if (request_.compare_sources)
      source_maps_ = std::make_unique<msf::SourceMaps>(on_rig_, source_.calibration());
  }

  /// After each frame is integrated, on the engine's integration thread.
  void onFrame(msf::FrameResult& r) {
    report_.frames.push_back({r.index, r.name, r.times,
                              r.times.load_ms + r.times.depth_ms + r.times.fusion_ms + r.times.integrate_ms,
                              msf::residentMemoryMb(), r.lidar_stereo_disagreement});
    used_poses_.push_back(r.T_world_cam0);
    if (sky_) {
      sky_->setPose(r.index, r.T_world_cam0);
      name_of_[r.index] = r.name;
    }
    cv::Mat true_depth, moving; // moving: read once for the synthetic scores and protocol 4
    if (truth_) {
      true_depth = truth_->depth(r.name);
      if (!streaming()) // the meshes are scored
        moving = truth_->truth().movingMask(truth_->truth().indexOf(r.name));
      truth_->addFrame(r, true_depth, source_.calibration(), on_rig_.integrator.max_depth_m, moving);
    }
    if (evaluation_) {
      if (!moving_split_)
        moving.release(); // no moving masks: protocol 4 splits no pixel off as moving
      if (request_.holdout) {
        evaluation_->addGroundTruth(r.index, r.T_world_cam0, holdout_.take(r.index), moving);
        // The held-out rings do not say what moved; the scans of the frames around them do.
        evaluation_->addScan(r.index, r.T_world_cam0 * source_.calibration().T_cam0_velo, r.scan_free_space);
      } else {
        evaluation_->addGroundTruth(r.index, r.T_world_cam0, true_depth, moving);
      }
      evaluation_->scoreDepth("fused", r.index, r.fused.depth);
    }
    if (source_maps_)
      source_maps_->integrate(r);
    if (request_.save_depth)
      msf::saveCloud(path("depth/" + r.name + ".pcd"), msf::fusedCloud(r, source_.calibration()));
    if (panel_frames_.count(r.index)) {
      const std::string name = "depth_" + r.name + ".png";
      msf::writeImage(path(name), msf::framePanel(r, request_.holdout, true_depth));
      report_.depth_panels.push_back(name);
    }
  }

  /// The paper as published (-compare_paper) on the same frames, after ours: its own engine
  /// with PipelineConfig::paper() on our grid and rings, at the poses ours used.
  void runPaper() {
    msf::PipelineConfig paper = msf::PipelineConfig::paper();
    paper.volume = config_.volume;
    paper.rings = config_.rings;
    paper.validate();
    msf::Reconstructor::Options options;
    options.poses = msf::Reconstructor::PoseMode::Given;
    paper_ = std::make_unique<msf::Reconstructor>(source_.calibration(), paper, options);
    std::map<std::size_t, Eigen::Isometry3d> pose_of;
    for (std::size_t k = 0; k < used_poses_.size(); ++k)
      pose_of[frames_[k]] = used_poses_[k];
    const std::vector<std::size_t> done(frames_.begin(), frames_.begin() + static_cast<long>(used_poses_.size()));
    msf::RingHoldout split(source_, holdout_.config());
    paper_->setFrameFilter([&](msf::Frame& frame) {
      if (request_.holdout)
        split.split(frame);
      frame.T_world_cam0 = pose_of.at(frame.index);
      frame.has_pose = true;
    });
    print_highlight("Running the paper's method on the same frames ");
    TicToc tt;
    tt.tic();
    paper_->run(source_, done, [&](msf::FrameResult& p) {
      if (request_.holdout)
        split.take(p.index);
      if (truth_)
        truth_->addDepth("paper", p.name, truth_->depth(p.name), p.fused.depth,
                         source_.calibration().focalBaseline());
      if (evaluation_)
        evaluation_->scoreDepth("paper", p.index, p.fused.depth);
    });
    msf::tool::printDone(tt.toc(), done.size(), "frames");
  }

  void meshMaps() {
    if (request_.compare_paper && !used_poses_.empty())
      runPaper();
    TicToc tt;
    tt.tic();
    print_highlight(streaming() ? "Meshing the tiles in memory, writing the union " : "Meshing ");
    report_.observed_voxels = engine_->volume().numObservedVoxels();
    report_.blocks = engine_->volume().numBlocks();
    report_.volume_memory_mb = static_cast<double>(engine_->volume().memoryBytes()) / (1024.0 * 1024.0);
    // A streamed map's mesh is on disk (the union of OUT/tiles in OUT/mesh.ply), not in memory.
    const std::size_t streamed_triangles = streaming() ? engine_->finishStreaming(path(report_.mesh_file)) : 0;
    mesh_ = streaming() ? &streamed_ : &engine_->mesh();
    report_.mesh_ms = tt.toc();
    msf::tool::printDone(report_.mesh_ms, streaming() ? streamed_triangles : mesh_->triangles.size(), "triangles");
    report_.vertices = mesh_->vertices.size();
    report_.triangles = streaming() ? streamed_triangles : mesh_->triangles.size();
    report_.pieces_removed = engine_->meshStats().components_removed;
    report_.triangles_removed = engine_->meshStats().triangles_removed;
    if (streaming()) {
      const msf::StreamingMap::Stats& st = engine_->streaming()->stats();
      print_info("Streamed: %zu tiles written, %zu read back (%zu on allocation), %zu meshed again; %zu blocks freed; "
                 "%.0f ms in all\n",
                 st.tiles_written, st.tiles_reloaded, st.tiles_reloaded_on_allocation, st.tiles_remeshed,
                 st.blocks_freed, st.stream_ms);
    }
    if (paper_) {
      tt.tic();
      print_highlight("Meshing the paper's map ");
      paper_mesh_ = &paper_->mesh();
      msf::tool::printDone(tt.toc(), paper_mesh_->triangles.size(), "triangles");
    }
    if (source_maps_ && hurried()) { // stopped twice: the single-source maps are not meshed
      report_.skipped.push_back("compare_sources");
      source_maps_.reset();
    }
    if (source_maps_) {
      tt.tic();
      print_highlight("Meshing the map of each source alone ");
      source_maps_->mesh();
      msf::tool::printDone(tt.toc(), source_maps_->maps().size(), "maps");
    }
  }

  void saveMeshes() {
    TicToc tt;
    tt.tic();
    print_highlight("Saving ");
    print_value("%s/{%s%s} ", request_.out.c_str(),
                streaming() ? "config.yaml (mesh.ply, tiles/, tsdf/ are written)" : "mesh.ply, volume.pcd",
                source_maps_ ? ", mesh_lidar.ply, mesh_stereo.ply" : "");
    mesh_->toPolygonMesh(polygons_["mesh"]);
    if (streaming()) {
      if (report_.triangles == 0)
        print_warn("\nno surface was reconstructed: mesh.ply is not written\n");
      else if (!T_out_world_.matrix().isIdentity())
        msf::StreamingMap::transformMeshFile(path(report_.mesh_file), T_out_world_);
    } else if (!mesh_->triangles.empty()) {
      saveInOutputWorld(report_.mesh_file, polygons_["mesh"]);
      engine_->volume().save(path(report_.volume_file));
    } else {
      print_warn("\nno surface was reconstructed: mesh.ply and volume.pcd are not written\n");
    }
    if (source_maps_)
      for (const auto& map : source_maps_->maps())
        saveNonEmpty(map->name(), map->mesh);
    if (paper_mesh_)
      saveNonEmpty("mesh_paper", *paper_mesh_);
    msf::writeAtomically(path(report_.config_file), [&](const std::string& tmp) {
      std::ofstream file(tmp);
      file << report_.config_yaml;
      if (!file)
        throw msf::IOError("cannot write '" + tmp + "'");
    });
    msf::tool::printDone(tt.toc(), mesh_->vertices.size(), "vertices");
    if (!mesh_->triangles.empty() && hurried())
      report_.skipped.push_back("mesh_preview");
    else if (!mesh_->triangles.empty())
      msf::writeMeshPreview(stage_, *mesh_, source_.calibration(), used_poses_.front(), report_);
  }

  void saveNonEmpty(const std::string& name, const msf::TriangleMesh& mesh) {
    if (mesh.triangles.empty())
      return;
    mesh.toPolygonMesh(polygons_[name]);
    saveInOutputWorld(name + ".ply", polygons_[name]);
  }

  /// A mesh file in the output's world (-world); `mesh` stays in the map's, for the scores.
  void saveInOutputWorld(const std::string& name, const pcl::PolygonMesh& mesh) const {
    if (T_out_world_.matrix().isIdentity())
      return msf::saveMesh(path(name), mesh);
    pcl::PolygonMesh moved = mesh;
    msf::transformMesh(moved, T_out_world_);
    msf::saveMesh(path(name), moved);
  }

  using MeshesToScore = std::map<std::string, msf::SyntheticScoring::MeshToScore>;
  using MeshScores = std::map<std::string, msf::SyntheticScoring::MeshScores>;

  /// The meshes against the true surface (synthetic), then seen from every frame's pose
  /// (protocol 4, protocol 6, the synthetic true sky).
  void scoreMeshes() {
    MeshesToScore meshes;
    if (!streaming())
      meshes["mesh"] = {mesh_, &polygons_["mesh"]};
    if (source_maps_)
      for (const auto& map : source_maps_->maps())
        meshes[map->name()] = {&map->mesh, polygons_.count(map->name()) ? &polygons_[map->name()] : nullptr};
    if (paper_mesh_)
      meshes["mesh_paper"] = {paper_mesh_, polygons_.count("mesh_paper") ? &polygons_["mesh_paper"] : nullptr};
    MeshScores scores;
    if (truth_)
      truth_->writeDepthScores(report_);
    if (truth_ && goesAhead("mesh_accuracy")) {
      TicToc tt;
      tt.tic();
      print_highlight("Scoring the mesh%s against ", meshes.size() > 1 ? "es" : "");
      print_value("%s ", truth_->truth().sceneMeshPath().c_str());
      scores = truth_->scoreMeshes(meshes, config_.volume.voxel_size_m);
      if (scores.count("mesh")) {
        report_.mesh_accuracy = scores["mesh"].accuracy;
        report_.has_mesh_accuracy = true;
      }
      msf::tool::printDone(tt.toc(), scores.size(), "meshes");
    }
    scoreViews(meshes, scores);
  }

  /// Whether a step after the run goes ahead: not once stopped twice (said in the summary).
  bool goesAhead(const char* step) {
    if (!hurried())
      return true;
    report_.skipped.push_back(step);
    return false;
  }

  /// Each mesh rendered at every frame's pose once for all that score its views: protocol 4
  /// at the ground truth's pixels, protocol 6 over the open sky, and the synthetic true sky.
  void scoreViews(const MeshesToScore& meshes, MeshScores& scores) {
    const bool protocol4 = evaluation_ && goesAhead("reconstruction_evaluation");
    const bool protocol6 = sky_ && !meshes.empty() && goesAhead("open_sky");
    if (!protocol4 && !protocol6 && scores.empty())
      return;
    TicToc tt;
    tt.tic();
    print_highlight("Rendering the mesh%s at every frame's pose ", meshes.size() > 1 ? "es" : "");
    std::size_t views = 0;
    std::map<std::string, msf::SeenThroughPieces> seen_through;
    for (const auto& [name, m] : meshes) {
      msf::MeshViewScoring scoring;
      if (protocol4)
        evaluation_->addViews(scoring, name);
      if (protocol6)
        sky_->addViews(scoring, name, name == "mesh"); // the pictures show the fused mesh
      msf::SyntheticScoring::TrueSky true_sky;
      const auto score = scores.find(name);
      if (score != scores.end())
        truth_->addTrueSkyViews(scoring, true_sky);
      views += scoring.score(*m.mesh);
      if (score != scores.end()) {
        score->second.true_sky = true_sky.all.coverage();
        score->second.true_sky_sheets = true_sky.sheets.coverage();
      }
      if (protocol4)
        seen_through[name] = evaluation_->seenThroughPieces(*m.mesh);
    }
    msf::tool::printDone(tt.toc(), views, "views");
    if (protocol4)
      summarizeProtocol4(scores, seen_through);
    if (protocol6) {
      report_.open_sky = sky_->scores();
      if (meshes.count("mesh"))
        report_.sky_pictures = sky_->drawPictures(stage_, name_of_);
    }
  }

  /// Protocol 4's rows into the report, each mesh's synthetic scores beside its row.
  void summarizeProtocol4(const MeshScores& scores, const std::map<std::string, msf::SeenThroughPieces>& seen_through) {
    msf::RunReport::MapEvaluation& e = report_.map_evaluation;
    e.truth = request_.holdout ? "held-out rings (ring id % " + std::to_string(config_.rings.modulo) + " == " +
                                     std::to_string(config_.rings.heldout_remainder) + ") projected into camera 0"
                               : "the synthetic sequence's exact depth (gt/depth_0)";
    e.range_m = on_rig_.integrator.max_depth_m;
    e.moving_split = moving_split_;
    e.transient_split = evaluation_->splitsTransient();
    bool any_ghosts = false;
    for (const auto& [name, s] : scores)
      any_ghosts = any_ghosts || s.has_ghosts;
    if (!any_ghosts)
      e.no_ghosts = truth_ ? truth_->noGhostsReason()
                           : "no synthetic ground truth: the places of moving objects are unknown";
    msf::summarizeMapEvaluation(*evaluation_, scores, seen_through, e);
  }

  const Request& request_;
  msf::PipelineConfig config_; // streamOnItsOwn may set its streaming radius
  const msf::FrameSource& source_;
  std::string stage_;
  std::vector<std::size_t> frames_;
  msf::PoseSource poses_;
  msf::RingHoldout holdout_;
  std::set<std::size_t> panel_frames_;
  Eigen::Isometry3d T_out_world_; // -world: from the map's world to the outputs'
  msf::PipelineConfig on_rig_; // the engine's configuration on the source's rig (adaptToRig): the map's range, the source maps'
  msf::RunReport report_;
  std::unique_ptr<msf::SyntheticScoring> truth_;
  std::unique_ptr<msf::ReconstructionEvaluation> evaluation_;
  std::unique_ptr<msf::SkyScoring> sky_;
  std::map<std::size_t, std::string> name_of_; // of the frames integrated, for protocol 6's pictures
  bool moving_split_ = false;
  std::unique_ptr<msf::SourceMaps> source_maps_;
  std::unique_ptr<msf::Reconstructor> engine_, paper_;
  msf::PoseList used_poses_;
  const msf::TriangleMesh* mesh_ = nullptr;
  const msf::TriangleMesh* paper_mesh_ = nullptr;
  msf::TriangleMesh streamed_; // a streamed map's mesh is on disk: this stays empty
  std::map<std::string, pcl::PolygonMesh> polygons_;
};

/// The options, which write into `request` and `config`.
void declareOptions(msf::tool::CommandLine& cli, Request& request, msf::PipelineConfig& config) {
  cli.value("-o", "DIR", request.out,
            "output folder (default {default}): mesh.ply, volume.pcd, summary.json, frames.csv, runtime.png, "
            "depth_<frame>.png, sky_<frame>.png, mesh_preview.png, report.md, config.yaml, poses.txt, poses_tum.txt, "
            "trajectory.png (and the maps of -compare_sources and -compare_paper). Absent, empty, or an earlier "
            "run's output (replaced); anything else in it is refused")
      .value("-config", "FILE",
             [&](const std::string& path) {
               config = msf::PipelineConfig::load(path);
               request.config_path = path;
             },
             "YAML configuration (config/kitti.yaml); the options below override it")
      .value("-frames", "a:b", request.frames, "frame range, inclusive (default: all)")
      .value("-world", "W", request.world,
             "camera: the outputs in the poses' world (the default): KITTI's and the odometry's is camera 0 of the "
             "first frame (x right, y down, z forward), a bag's tf world or a poses file's as they are | z_up: such "
             "a camera's world turned to x forward, y left, z up (ROS), a world already z-up left as it is: "
             "mesh*.ply, poses.txt, poses_tum.txt (volume.pcd and a streamed map's tiles/ and tsdf/ stay the map's "
             "own store, in the poses' world)")
      .value("-poses", "P", request.poses,
             "dataset: the dataset's poses as they are (the default for ground truth: KITTI odometry, synthetic) | "
             "refine: the dataset's GPS/INS poses refined by LiDAR odometry, their motion the prediction and a soft "
             "constraint of their accuracy (the default for KITTI raw's OXTS; section odometry, prior_*) | "
             "estimate: LiDAR odometry as each frame is loaded (the default without poses; section odometry) | "
             "a KITTI poses file, line i for frame i. OUT/poses.txt holds the poses used")
      .value("-voxel", "V", config.volume.voxel_size_m, "voxel size in metres (tsdf_volume.voxel_size_m)")
      .value("-lambda", "L", config.integrator.lambda, "regularization of eq. 7 (tsdf_integrator.lambda)")
      .value("-panels", "N", request.panels,
             "depth panels to draw, spread over the frames (default {default}, at most " + std::to_string(kMaxPanels) +
                 ")")
      .value("-stream", "R", config.streaming.active_radius_m,
             "keep only R metres around the camera in memory (streaming.active_radius_m; at least the integrator's "
             "reach + a tile, 101 m with the shipped configs): the rest is meshed into OUT/tiles/X_Y_Z.ply and its TSDF "
             "written to OUT/tsdf/ as it leaves; mesh.ply is their union (no volume.pcd, no mesh scores, no preview; "
             "msf_mesh OUT out.ply meshes the TSDF again). See docs/streaming.md")
      .value("-max_memory", "MB", config.volume.max_memory_mb,
             "memory budget of the run (tsdf_volume.max_memory_mb; 0: 3/4 of RAM): with the poses known before the "
             "run (the dataset's or a file's), a run whose predicted peak exceeds it is refused before it starts; "
             "the TSDF volume also stops the run at the first frame whose blocks would not fit")
      .flag("-save_depth", request.save_depth, "also write each frame's fused depth as OUT/depth/NNNNNN.pcd")
      .flag("-holdout", request.holdout,
            "evaluation protocol 4: the held-out rings (config section rings) are removed from every scan before the "
            "pipeline sees it and become the ground truth; the mesh, rendered at every frame's pose, is scored at "
            "them beside the fused depth")
      .flag("-compare_sources", request.compare_sources,
            "also integrate the interpolated LiDAR alone and SGBM alone into volumes of their own (mesh_lidar.ply, "
            "mesh_stereo.ply), scored as the mesh is")
      .flag("-compare_paper", request.compare_paper,
            "also run the paper as published (config/paper.yaml: docs/paper.md) on the same frames into a map of its "
            "own (mesh_paper.ply); its per-frame depth (paper) and mesh are scored beside ours")
      .note("With ground truth (-holdout, or a synthetic sequence's gt/), summary.json and report.md hold the "
            "protocol 4 rows: mesh, fused (and mesh_lidar, mesh_stereo, mesh_paper, paper), within the map's depth "
            "range and all.\n"
            "OUT/config.yaml is the configuration in full; -config OUT/config.yaml -o OTHER repeats the run.")
      .note("Ctrl-C (or SIGTERM) stops after the frames under way and still writes the mesh and the summary (exit "
            "code 130); a second one also skips the mesh's scores and renderings (summary.json lists them under "
            "\"skipped\"); later ones are ignored until the mesh and the summary are written.");
  msf::addDatasetOptions(cli, request.reader);
}

/// The DATASET_DIR argument ("" for the default street); refuses more than one.
std::string datasetArgument(const msf::tool::Arguments& positional, const msf::tool::CommandLine& cli) {
  if (positional.size() > 1) {
    std::string extra, flags;
    for (std::size_t k = 1; k < positional.size(); ++k)
      extra += (k > 1 ? "', '" : "") + positional[k];
    for (const std::string& flag : cli.flags())
      flags += (flags.empty() ? "" : ", ") + flag;
    throw msf::InvalidInputError("expected at most one DATASET_DIR, got '" + positional.front() + "' and '" + extra +
                                 "' too (" + flags + " take no value; see -h)");
  }
  return positional.empty() ? "" : positional.front();
}

/// Refuses what the options cannot do together, before any folder is made.
void checkRequest(const Request& request, const msf::PipelineConfig& config) {
  config.validate();
  if (request.panels < 0 || request.panels > kMaxPanels)
    throw msf::InvalidInputError("-panels must be 0.." + std::to_string(kMaxPanels) + ", not " +
                                 std::to_string(request.panels));
  const bool streaming = config.streaming.enabled();
  if (streaming && config.mesher.min_component_triangles > 0)
    std::printf("Note: a streamed map keeps its small pieces (marching_cubes.min_component_triangles is not "
                "applied): its tiles are meshed apart, and a piece may cross them\n");
  if (streaming && (request.holdout || request.compare_sources || request.compare_paper))
    throw msf::InvalidInputError(std::string(request.holdout           ? "-holdout"
                                             : request.compare_sources ? "-compare_sources"
                                                                       : "-compare_paper") +
                                 " needs the whole map in memory: not with a streamed map (-stream, " +
                                 "streaming.active_radius_m)");
  msf::FrameRange::parse(request.frames); // a malformed range
}

/// The run, into the output folder it commits at the end; the exit code (130: stopped).
int reconstruct(const Request& request, const msf::PipelineConfig& config) {
  // OUT is replaced as a whole: an input inside it is refused.
  const bool poses_file = !request.poses.empty() && request.poses != "dataset" && request.poses != "estimate" &&
                          request.poses != "refine";
  installStopHandler();
  msf::OutputFolder output(request.out, "msf_reconstruct",
                           {request.dataset, request.config_path, poses_file ? request.poses : "", request.reader.rig});
  // The default street is generated inside the staging folder (a killed run's goes with it
  // at the next run) and removed before the commit.
  const fs::path street = fs::path(output.dir()) / ".street";
  const std::unique_ptr<msf::FrameSource> source = msf::openDataset(
      request.dataset.empty() ? generateDefaultStreet(street.string()) : request.dataset, request.reader);
  for (const std::string& note : source->notes())
    print_warn("%s: %s\n", source->description().c_str(), note.c_str());
  if (request.save_depth)
    fs::create_directories(fs::path(output.dir()) / "depth");

  Run run(request, config, *source, output.dir());
  const bool interrupted = run.reconstruct();
  run.finish(interrupted);
  std::error_code ec;
  fs::remove_all(street, ec);
  output.commit();
  printSummary(run.report(), request.out);
  return interrupted ? 130 : 0;
}

} // namespace

int main(int argc, char** argv) {
  Request request;
  msf::PipelineConfig config;
  msf::tool::CommandLine cli(
      "msf_reconstruct", "[DATASET_DIR] [options]",
      "Reconstructs a dataset (a folder of the generic layout with a rig file, a KITTI odometry sequence or raw drive, "
      "a synthetic sequence of msf_synth, a ROS 1 bag in kitti2bag's layout or with the topics named below: "
      "docs/ros.md) into a coloured mesh: LiDAR projection + compound interpolation and SGBM stereo, fused per pixel, integrated into a "
      "regularized TSDF, meshed by marching cubes. Without DATASET_DIR it generates the default synthetic street "
      "(20 frames) in a temporary folder and reconstructs it.");
  declareOptions(cli, request, config);
  return cli.run(argc, argv, 0, [&](const msf::tool::Arguments& positional) {
    request.dataset = datasetArgument(positional, cli);
    checkRequest(request, config);
    return reconstruct(request, config);
  });
}
