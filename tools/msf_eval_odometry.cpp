// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_eval_odometry: evaluation protocol 5 of an estimated trajectory against a reference,
// with a picture of both from above.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/datasets/open_dataset.h>
#include <msf/evaluation/odometry_metrics.h>
#include <msf/evaluation/trajectory_plot.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>

#include <pcl/console/print.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

msf::PoseList loadReference(const std::string& path, const std::string& frames_text) {
  msf::PoseList all;
  if (fs::is_directory(path)) {
    const auto dataset = msf::openDataset(path);
    if (!dataset->hasPoses())
      throw msf::InvalidInputError("dataset '" + path + "' has no poses (odometry poses/XX.txt, raw oxts/, gt/ or "
                                   "your layout's poses.txt) to compare with");
    all = dataset->referencePoses(); // the truth, when the dataset's poses are a synthetic INS's
  } else {
    all = msf::loadOdometryPoses(path);
  }
  if (frames_text.empty())
    return all;
  const msf::FrameRange range = msf::FrameRange::parse(frames_text);
  const auto last = range.last < 0 ? static_cast<int>(all.size()) - 1 : range.last;
  if (last >= static_cast<int>(all.size()))
    throw msf::InvalidInputError("-frames " + frames_text + ": the reference '" + path + "' has " +
                                 std::to_string(all.size()) + " poses");
  return msf::PoseList(all.begin() + range.first, all.begin() + last + 1);
}

} // namespace

int main(int argc, char** argv) {
  std::string plot_path, frames_text;
  bool overwrite = false;
  msf::tool::CommandLine cli(
      "msf_eval_odometry", "est.txt REFERENCE [options]",
      "Scores an estimated trajectory (KITTI poses format: T_world_cam0, a 3x4 row-major matrix a line, one line per "
      "frame) against REFERENCE: a poses file of the same frames, or a dataset folder whose poses are the reference "
      "(KITTI odometry poses, a raw drive's OXTS, a synthetic sequence's ground truth, your own layout's poses.txt). Evaluation protocol 5:\n"
      "  KITTI devkit translation error (%) and rotation error (deg/m) over segments of 100..800 m from every 10th "
      "frame, or, on a path shorter than 100 m, of k/8 of its length (k = 1..7) from every frame; absolute "
      "trajectory error (RMSE of the positions) and end-point drift (in m and in % of the path length), both after "
      "moving the estimate so that its first pose is the reference's (no other alignment, as KITTI).");
  cli.value("-frames", "a:b", frames_text,
            "the reference's frames a..b (its file's lines, 0-based), when the estimate covers part of the sequence "
            "(msf_odometry -frames a:b)")
      .value("-plot", "FILE", plot_path,
             "PNG of both trajectories from above, in the reference's first camera frame (default: next to est.txt, "
             "<name>_trajectory.png)")
      .overwriteOption(overwrite);
  return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& positional) {
    if (positional.size() != 2)
      throw msf::InvalidInputError("expected est.txt and a reference, got " + std::to_string(positional.size()) +
                                   " positional arguments (see -h)");
    const std::string estimate_path = positional[0], reference_path = positional[1];
    if (!cli.given("-plot")) {
      const fs::path est(estimate_path);
      plot_path = (est.parent_path() / (est.stem().string() + "_trajectory.png")).string();
    }
    if (msf::fileExtension(plot_path) != ".png")
      throw msf::InvalidInputError("-plot '" + plot_path + "': the picture is a .png");
    msf::tool::requireNewOutputs({plot_path}, overwrite);

    const msf::PoseList estimate = msf::loadOdometryPoses(estimate_path);
    const msf::PoseList reference = loadReference(reference_path, frames_text);
    if (estimate.size() != reference.size())
      throw msf::InvalidInputError("'" + estimate_path + "' has " + std::to_string(estimate.size()) + " poses and '" +
                                   reference_path + "' " + std::to_string(reference.size()) +
                                   (fs::is_directory(reference_path) ? "" : " (use -frames a:b for part of a sequence)"));
    const msf::OdometryMetrics m = msf::evaluateOdometry(estimate, reference);

    print_info("%zu poses, reference path %.2f m\n", m.poses, m.path_length_m);
    print_info("KITTI devkit, %zu segments of ", m.segments);
    if (m.devkit_lengths)
      print_info("100-800 m (every 10th frame)");
    else
      print_info("%.2f-%.2f m (k/8 of the path, k = 1..7, every frame; the path is shorter than 100 m)",
                 m.segment_lengths_m.front(), m.segment_lengths_m.back());
    print_info(":\n  translation error ");
    print_value("%.3f %%", m.translation_error_pct);
    print_info("\n  rotation error    ");
    print_value("%.5f deg/m", m.rotation_error_deg_per_m);
    print_info("\nFirst poses aligned (no other alignment):\n  ATE               ");
    print_value("%.4f m", m.ate_rmse_m);
    print_info(" RMSE (mean %.4f m, max %.4f m)\n  end-point drift   ", m.ate_mean_m, m.ate_max_m);
    print_value("%.4f m = %.3f %%", m.end_drift_m, m.end_drift_pct);
    print_info(" of the path, rotation %.4f deg\n", m.end_rotation_error_deg);

    msf::writeImage(plot_path, msf::plotTrajectoriesFromAbove(
        {{"reference", reference}, {"estimate", msf::alignFirstPose(estimate, reference)}}));
    print_info("Plot: ");
    print_value("%s\n", plot_path.c_str());
    return 0;
  });
}
