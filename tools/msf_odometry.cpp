// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_odometry: camera 0's trajectory of a sequence from its LiDAR scans (the tracking module),
// in KITTI's poses format.
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/tool.h>
#include <msf/datasets/open_dataset.h>
#include <msf/evaluation/odometry_metrics.h>
#include <msf/io/poses.h>
#include <msf/registration/lidar_odometry.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace pcl::console;

namespace {

void printMetrics(const msf::OdometryMetrics& m) {
  print_info("  ATE (first poses aligned) ");
  print_value("%.3f m", m.ate_rmse_m);
  print_info(" RMSE, %.3f m max; end-point drift ", m.ate_max_m);
  print_value("%.3f m = %.2f %%", m.end_drift_m, m.end_drift_pct);
  print_info(" of %.1f m, %.3f deg\n", m.path_length_m, m.end_rotation_error_deg);
  print_info("  KITTI devkit over %zu segments of %s: translation ", m.segments,
             m.devkit_lengths ? "100-800 m" : "k/8 of the path (k = 1..7; the devkit's 100 m is longer than the path)");
  print_value("%.2f %%", m.translation_error_pct);
  print_info(", rotation ");
  print_value("%.4f deg/m\n", m.rotation_error_deg_per_m);
}

/// What the command line sets.
struct Settings {
  std::string output, config_path, frames_text = "0:";
  msf::DatasetOptions reader;
  bool print_config = false, overwrite = false;
};

/// Camera 0's pose of each frame tracked, and the time each scan's registration took.
struct Track {
  msf::PoseList T_world_cam0;
  std::vector<double> register_ms;
};

/// A frame's line: on a terminal the progress in place, else the registration's figures.
void printProgress(const msf::FrameSource& sequence, const std::vector<std::size_t>& frames, std::size_t k,
                   double register_ms, const msf::LidarOdometry::Stats& s, double elapsed_s, bool tty) {
  const double fps = static_cast<double>(k + 1) / elapsed_s;
  if (tty)
    std::printf("\r  frame %zu/%zu  %.1f fps  %.0f s left   ", k + 1, frames.size(), fps,
                static_cast<double>(frames.size() - k - 1) / fps);
  else
    std::printf("  frame %s (%zu/%zu): %.1f ms, %zu points, %d iterations, threshold %.2f m, constraint %.3f, "
                "map %zu points\n",
                sequence.frameName(frames[k]).c_str(), k + 1, frames.size(), register_ms, s.source_points,
                s.iterations, s.threshold_m, s.constraint, s.map_points);
  std::fflush(stdout);
}

/// Registers the scans of `frames` in turn; the first frame is at the dataset's pose.
Track track(const msf::FrameSource& sequence, const std::vector<std::size_t>& frames,
            const msf::LidarOdometry::Config& config) {
  const msf::Calibration& calibration = sequence.calibration();
  const Eigen::Isometry3d T_world_cam0_first =
      sequence.hasPoses() ? sequence.referencePoses()[frames.front()] : Eigen::Isometry3d::Identity();
  print_highlight("Tracking ");
  print_value("%zu", frames.size());
  print_info(" frames of ");
  print_value("%s\n", sequence.description().c_str());
  msf::LidarOdometry odometry(msf::resolveDeskew(config, sequence));
  Track result;
  const bool tty = ::isatty(STDOUT_FILENO);
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const auto scan = sequence.loadScan(frames[k]);
    TicToc tt;
    tt.tic();
    const Eigen::Isometry3d T_velo0_velo = odometry.registerScan(*scan, sequence.scanName(frames[k]));
    result.register_ms.push_back(tt.toc());
    result.T_world_cam0.push_back(msf::cameraPose(T_velo0_velo, calibration.T_cam0_velo, T_world_cam0_first));
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    printProgress(sequence, frames, k, result.register_ms.back(), odometry.lastStats(), elapsed, tty);
  }
  if (tty)
    std::printf("\n");
  print_info("Registration: median ");
  print_value("%.1f ms", msf::median(result.register_ms));
  print_info(", p95 %.1f ms per frame (loading apart)\n", msf::percentile(result.register_ms, 95));
  return result;
}

int run(const msf::tool::Arguments& positional, const Settings& settings) {
  if (positional.size() != 1)
    throw msf::InvalidInputError("expected one DATASET_DIR, got " + std::to_string(positional.size()) +
                                 " positional arguments (see -h)");
  if (settings.output.empty())
    throw msf::InvalidInputError("no output file: give -o poses.txt");
  msf::tool::requireNewOutputs({settings.output}, settings.overwrite);
  msf::LidarOdometry::Config config;
  if (!settings.config_path.empty())
    msf::readConfigSection(settings.config_path, config);
  if (settings.print_config)
    msf::printConfig(std::cout, config);

  const auto source = msf::openDataset(positional.front(), settings.reader);
  const msf::FrameSource& sequence = *source;
  const std::vector<std::size_t> frames = sequence.indices(msf::FrameRange::parse(settings.frames_text));
  const Track tracked = track(sequence, frames, config);

  TicToc tt;
  tt.tic();
  print_highlight("Saving ");
  print_value("%s ", settings.output.c_str());
  msf::saveOdometryPoses(settings.output, tracked.T_world_cam0);
  msf::tool::printDone(tt.toc(), tracked.T_world_cam0.size(), "poses");

  if (sequence.hasPoses()) {
    msf::PoseList reference;
    for (std::size_t i : frames)
      reference.push_back(sequence.referencePoses()[i]);
    print_info("Against %s:\n", sequence.referencePosesName().c_str());
    printMetrics(msf::evaluateOdometry(tracked.T_world_cam0, reference));
  }
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::tool::CommandLine cli(
      "msf_odometry", "DATASET_DIR -o poses.txt [options]",
      "Estimates camera 0's pose of every frame from the LiDAR scans alone (LidarOdometry: each scan registered to a "
      "local map of the scans before it) and writes T_world_cam0 in KITTI's poses format, a 3x4 row-major matrix a "
      "line, one line per frame run. DATASET_DIR: what msf_reconstruct reads (a KITTI odometry sequence or raw "
      "drive, a synthetic sequence of msf_synth, a folder of your own rig's layout, a ROS 1 bag). The first frame is at the dataset's pose when it has poses (the identity on KITTI), "
      "else at the identity; with poses, the estimate is also scored against them (evaluation protocol 5, "
      "msf_eval_odometry).");
  cli.value("-o", "FILE", settings.output, "output poses file (written whole or not at all)")
      .value("-frames", "a:b", settings.frames_text, "frame range, inclusive (default: all)")
      .value("-config", "FILE", settings.config_path, "YAML configuration; its `odometry` section (config/kitti.yaml)")
      .flag("-print_config", settings.print_config, "print the configuration in effect")
      .overwriteOption(settings.overwrite);
  msf::addDatasetOptions(cli, settings.reader);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) { return run(positional, settings); });
}
