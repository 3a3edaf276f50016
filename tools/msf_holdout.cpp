// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Evaluation protocol 2 (docs/design.md): ring hold-out on real KITTI scans. One row per
// method: the table a user compares depth methods with. On a synthetic sequence (gt/ beside
// it, protocol 3) the whole scan is the input and every pixel of gt/depth_0 is ground truth,
// reported for all, background and foreground pixels (the paper's Table 1).
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/tool.h>
#include <msf/evaluation/holdout.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/scan_history.h>
#include <msf/stereo/sgbm_stereo.h>
#include <msf/synthetic/ground_truth.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

/// A named method: from the config to a function of one frame's input.
struct MethodEntry {
  const char* name;
  const char* description;
  std::function<msf::HoldoutMethod(const msf::ConfigFile&)> make;
};

/// A LiDAR method: the input rings completed by `method` (projection on the canvas included).
msf::HoldoutMethod lidar(const msf::ConfigFile& file, msf::CompletionMethod method) {
  const auto projection = file.get<msf::ProjectionConfig>();
  const auto interpolation = file.get<msf::InterpolationConfig>();
  const auto ip_basic = file.get<msf::IpBasicConfig>();
  std::shared_ptr<msf::LidarCompletion> completion; // made at the first frame, which has the calibration
  return [=](const msf::HoldoutInput& in) mutable {
    if (!completion)
      completion = std::make_shared<msf::LidarCompletion>(*in.calibration, method, projection, interpolation, ip_basic);
    cv::Mat depth;
    completion->computeDepth(*in.scan, depth);
    return depth;
  };
}

/// How SGBM uses the input rings.
enum class StereoInput {
  None,   ///< the grey pair alone
  Prior,  ///< its search narrowed by the compound interpolation of the input rings, unguided
  Guided  ///< the same, and guided by the projected input rings
};

/// SGBM on the grey pair (section stereo); the time of the LiDAR it uses counts too.
msf::HoldoutMethod stereo(const msf::ConfigFile& file, StereoInput input) {
  auto config = file.get<msf::SgbmConfig>();
  config.guidance = input == StereoInput::Guided ? "lidar" : "none";
  const auto projection = file.get<msf::ProjectionConfig>();
  auto completion = lidar(file, msf::CompletionMethod::Compound);
  auto sgbm = std::make_shared<msf::SgbmStereo>(config);
  std::shared_ptr<msf::LidarProjector> projector;
  return [=](const msf::HoldoutInput& in) mutable {
    sgbm->setCalibration(*in.calibration);
    sgbm->setInputImages(in.left, in.right);
    sgbm->setDepthPrior(input != StereoInput::None ? completion(in) : cv::Mat());
    cv::Mat sparse;
    if (input == StereoInput::Guided) {
      if (!projector)
        projector = std::make_shared<msf::LidarProjector>(*in.calibration, projection);
      projector->projectToImage(*in.scan, sparse); // the input rings only
    }
    sgbm->setGuidance(sparse);
    sgbm->computeDisparity();
    return sgbm->getDepth();
  };
}

/// The input rings with the agreeing returns of the earlier frames' input rings (ScanHistory,
/// section accumulation), placed by the sequence's poses; the input rings alone for a frame
/// without a pose or with accumulation.scans 0. Frames come in order.
std::function<const pcl::PointCloud<pcl::PointXYZI>&(const msf::HoldoutInput&)>
withEarlierScans(const msf::ProjectionConfig& projection, const msf::ScanHistoryConfig& accumulation) {
  std::shared_ptr<msf::ScanHistory> history;
  return [=](const msf::HoldoutInput& in) mutable -> const pcl::PointCloud<pcl::PointXYZI>& {
    if (!history)
      history = std::make_shared<msf::ScanHistory>(*in.calibration, projection, accumulation);
    const Eigen::Isometry3d T_world_velo = in.T_world_cam0 * in.calibration->T_cam0_velo;
    return history->withEarlierScans(*in.scan, in.has_pose ? &T_world_velo : nullptr);
  };
}

/// Compound interpolation of the input rings with the earlier frames' (withEarlierScans).
msf::HoldoutMethod accumulated(const msf::ConfigFile& file) {
  const auto projection = file.get<msf::ProjectionConfig>();
  const auto interpolation = file.get<msf::InterpolationConfig>();
  auto scans = withEarlierScans(projection, file.get<msf::ScanHistoryConfig>());
  std::shared_ptr<msf::LidarCompletion> completion;
  return [=](const msf::HoldoutInput& in) mutable {
    if (!completion)
      completion = std::make_shared<msf::LidarCompletion>(*in.calibration, msf::CompletionMethod::Compound,
                                                          projection, interpolation);
    cv::Mat depth;
    completion->computeDepth(scans(in), depth);
    return depth;
  };
}

/// Paper steps 1-4 with the stages' configurations: compound interpolation of the input
/// rings (with the earlier frames' agreeing returns, section accumulation), SGBM (narrowed by it
/// with stereo.prior_search_range, guided by its real returns with stereo.guidance lidar), and the
/// per-pixel fusion of the two, with the facade extension after it (fusion.facade_extension) as in
/// the pipeline.
msf::HoldoutMethod fusedWith(const msf::ProjectionConfig& projection, const msf::InterpolationConfig& interpolation,
                             const msf::ScanHistoryConfig& accumulation, const msf::SgbmConfig& stereo_config,
                             const msf::DepthFusionConfig& fusion) {
  std::shared_ptr<msf::LidarCompletion> completion;
  auto scans = withEarlierScans(projection, accumulation);
  auto sgbm = std::make_shared<msf::SgbmStereo>(stereo_config);
  auto fuser = std::make_shared<msf::DepthImageFusion>(fusion);
  return [=](const msf::HoldoutInput& in) mutable {
    if (!completion)
      completion = std::make_shared<msf::LidarCompletion>(*in.calibration, msf::CompletionMethod::Compound,
                                                          projection, interpolation);
    const pcl::PointCloud<pcl::PointXYZI>& scan = scans(in);
    cv::Mat lidar_depth, distance, depth;
    completion->computeDepth(scan, lidar_depth, &distance);
    sgbm->setCalibration(*in.calibration);
    sgbm->setInputImages(in.left, in.right);
    sgbm->setDepthPrior(lidar_depth);
    cv::Mat sparse;
    if (stereo_config.lidarGuidance())
      completion->projector().projectToImage(scan, sparse); // the input rings (and earlier scans') only
    sgbm->setGuidance(sparse);
    sgbm->computeDisparity();
    fuser->setCalibration(*in.calibration);
    fuser->setInputImage(in.left);
    fuser->setSkyImage(msf::skyImage(in.color, in.left, in.left.size())); // as the engine
    fuser->fuse(lidar_depth, distance, sgbm->getDepth(), sgbm->getConfidence(), depth);
    fuser->fillSmallHoles(depth);
    return depth;
  };
}

/// The same with the sections of `file` (section fusion, its method forced to `method` when given).
msf::HoldoutMethod fused(const msf::ConfigFile& file, std::optional<msf::FusionMethod> method,
                         std::optional<int> earlier_scans = std::nullopt) {
  auto fusion = file.get<msf::DepthFusionConfig>();
  fusion.method = method.value_or(fusion.method);
  auto accumulation = file.get<msf::ScanHistoryConfig>();
  accumulation.scans = earlier_scans.value_or(accumulation.scans);
  return fusedWith(file.get<msf::ProjectionConfig>(), file.get<msf::InterpolationConfig>(), accumulation,
                   file.get<msf::SgbmConfig>(), fusion);
}

/// The paper as published (PipelineConfig::paper, config/paper.yaml), whatever -config says:
/// its steps 1-4 beside ours on the same pixels.
msf::HoldoutMethod paper() {
  const msf::PipelineConfig c = msf::PipelineConfig::paper();
  return fusedWith(c.projection, c.interpolation, c.accumulation, c.stereo, c.fusion);
}

/// Add a method here (name -> function of the frame input) to get its row in the table.
const std::vector<MethodEntry>& methodTable() {
  static const std::vector<MethodEntry> table{
      {"interpolated", "compound interpolation (section interpolation)",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Compound); }},
      {"accumulated", "the same with the earlier frames' scans (section accumulation; needs poses)",
       [](const msf::ConfigFile& f) { return accumulated(f); }},
      {"linear", "the same slices, linear only",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Linear); }},
      {"cubic", "the same slices, zero-slope cubic only",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Cubic); }},
      {"ipbasic", "IP-Basic fast (Ku et al. 2018, section ip_basic), same projection",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::IpBasicFast); }},
      {"ipbasic_multiscale", "IP-Basic multiscale, same projection",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::IpBasicMultiscale); }},
      {"sgbm", "SGBM on the grey pair (section stereo: stereo.mode, stereo.engine), no LiDAR",
       [](const msf::ConfigFile& f) { return stereo(f, StereoInput::None); }},
      {"sgbm_prior", "the same, its search narrowed by the interpolated input rings, unguided",
       [](const msf::ConfigFile& f) { return stereo(f, StereoInput::Prior); }},
      {"sgbm_guided", "sgbm_prior guided by the projected input rings (stereo.guidance_*)",
       [](const msf::ConfigFile& f) { return stereo(f, StereoInput::Guided); }},
      {"fused", "steps 1-4 as the config says (fusion.method too): scripts/paper_additions.sh",
       [](const msf::ConfigFile& f) { return fused(f, std::nullopt); }},
      {"fused_single_scan", "the same from each frame's own scan alone (accumulation.scans 0)",
       [](const msf::ConfigFile& f) { return fused(f, std::nullopt, 0); }},
      {"fused_paper", "interpolated + SGBM fused by eq. 6 (section fusion; sgbm_guided with stereo.guidance lidar)",
       [](const msf::ConfigFile& f) { return fused(f, msf::FusionMethod::Paper); }},
      {"fused_uncertainty", "the same fused by inverse variance",
       [](const msf::ConfigFile& f) { return fused(f, msf::FusionMethod::Uncertainty); }},
      {"paper", "the paper as published, steps 1-4 (config/paper.yaml, not -config; docs/paper.md)",
       [](const msf::ConfigFile&) { return paper(); }},
  };
  return table;
}

std::string methodNames() {
  std::string names;
  for (const auto& m : methodTable())
    names += (names.empty() ? "" : ",") + std::string(m.name);
  return names;
}

/// The paper's Table 1 rows, the default methods of full-image (synthetic ground truth) mode.
const char* const kGroundTruthMethods = "sgbm,interpolated,fused_uncertainty,fused_paper,paper,ipbasic_multiscale";

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty())
      out.push_back(item);
  return out;
}

/// One method's rows in full-image mode: all, background and foreground pixels.
struct RegionResults {
  std::string method;
  msf::HoldoutResult region[3];
};
const char* const kRegionNames[3] = {"all", "background", "foreground"};

/// Full-image evaluation against synthetic ground truth: each method sees the whole scan
/// and the grey pair of a frame; its depth is compared at every pixel of gt/depth_0.
std::vector<RegionResults> runFullImage(const msf::Sequence& sequence, const std::vector<std::size_t>& frames,
                                        const std::vector<std::pair<std::string, msf::HoldoutMethod>>& methods,
                                        const msf::D1Threshold& d1) {
  const msf::synthetic::GroundTruth gt(sequence.groundTruthDir());
  const msf::Calibration& calibration = sequence.calibration();
  const double fB = calibration.focalBaseline();
  std::vector<std::array<msf::DepthErrorAccumulator, 3>> errors(methods.size());
  std::vector<std::vector<double>> times(methods.size());
  for (const std::size_t i : frames) {
    const std::size_t g = gt.indexOf(sequence.frameName(i));
    const cv::Mat gt_depth = gt.depth(g);
    const msf::synthetic::GroundTruth::Split split = gt.split(g, gt_depth);
    const cv::Mat masks[3] = {cv::Mat(), split.background, split.foreground};
    const msf::Frame frame = sequence.load(i, false);
    msf::HoldoutInput input;
    input.frame = i;
    input.calibration = &calibration;
    input.scan = frame.scan;
    input.left = frame.left;
    input.right = frame.right;
    input.has_pose = frame.has_pose;
    input.T_world_cam0 = frame.T_world_cam0;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      const auto start = std::chrono::steady_clock::now();
      const cv::Mat estimate = methods[m].second(input);
      const auto stop = std::chrono::steady_clock::now();
      times[m].push_back(std::chrono::duration<double, std::milli>(stop - start).count());
      if (estimate.type() != CV_32FC1 || estimate.size() != gt_depth.size())
        throw msf::InvalidInputError("method '" + methods[m].first + "' returned a " + std::to_string(estimate.cols) +
                                     "x" + std::to_string(estimate.rows) + " image of type " +
                                     std::to_string(estimate.type()) + ", expected CV_32FC1 " +
                                     std::to_string(gt_depth.cols) + "x" + std::to_string(gt_depth.rows) + " as '" +
                                     gt.depthPath(g) + "'");
      for (int r = 0; r < 3; ++r)
        errors[m][r].add(gt_depth, estimate, fB, masks[r], d1);
    }
  }
  std::vector<RegionResults> results;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const double median = msf::median(times[m]);
    RegionResults row;
    row.method = methods[m].first;
    for (int r = 0; r < 3; ++r) {
      row.region[r].method = methods[m].first;
      row.region[r].metrics = errors[m][r].metrics();
      row.region[r].median_ms = median;
      row.region[r].frames = frames.size();
    }
    results.push_back(row);
  }
  return results;
}

/// The protocol 2 columns with a region column after the method.
std::string formatRegionTable(const std::vector<RegionResults>& results) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-20s %-10s %9s %9s %9s %10s %9s %9s %9s %9s %10s\n", "method", "region",
                "coverage", "D1 all", "D1 est", "disp MAE", "MAE m", "RMSE m", "iMAE", "iRMSE", "ms/frame");
  out += line;
  for (const auto& row : results)
    for (int r = 0; r < 3; ++r) {
      const msf::DepthMetrics& m = row.region[r].metrics;
      std::snprintf(line, sizeof line, "%-20s %-10s %9.4f %8.2f%% %8.2f%% %8.3fpx %9.3f %9.3f %9.3f %9.3f %10.2f\n",
                    row.method.c_str(), kRegionNames[r], m.coverage, 100.0 * m.d1_all, 100.0 * m.d1_estimated,
                    m.disparity_mae_px, m.mae_m, m.rmse_m, m.imae_per_km, m.irmse_per_km, row.region[r].median_ms);
      out += line;
    }
  return out;
}

void writeRegionCsv(const std::string& path, const std::vector<RegionResults>& results) {
  msf::writeStreamAtomically(path, [&](std::ostream& out) {
    out << "method,region,frames,gt_pixels,estimated,coverage,d1_all,d1_estimated,disparity_mae_px,mae_m,rmse_m,"
           "imae_per_km,irmse_per_km,median_ms\n";
    out.precision(6);
    for (const auto& row : results)
      for (int r = 0; r < 3; ++r) {
        const msf::HoldoutResult& h = row.region[r];
        const msf::DepthMetrics& m = h.metrics;
        out << h.method << ',' << kRegionNames[r] << ',' << h.frames << ',' << m.gt_pixels << ',' << m.estimated << ','
            << m.coverage << ',' << m.d1_all << ',' << m.d1_estimated << ',' << m.disparity_mae_px << ',' << m.mae_m
            << ',' << m.rmse_m << ',' << m.imae_per_km << ',' << m.irmse_per_km << ',' << h.median_ms << '\n';
      }
  });
}

using NamedMethods = std::vector<std::pair<std::string, msf::HoldoutMethod>>;

/// What the command line sets.
struct Settings {
  std::string frames_text = "0:", methods_text, config_path, csv_path, bounds_text;
  bool gt_switch = false, holdout_switch = false, breakdown = false, overwrite = false;
};

/// The help of -methods: the table's methods, a line each.
std::string methodsHelp() {
  std::string help = std::string("methods, in this order (default: all; with gt/: ") + kGroundTruthMethods + "):";
  for (const auto& m : methodTable()) {
    char line[256];
    std::snprintf(line, sizeof line, "\n  %-19s %s", m.name, m.description);
    help += line;
  }
  return help;
}

/// Whether `sequence` is evaluated in full-image mode (it has gt/ and -holdout is not given),
/// after the options are checked against the mode; -methods defaults to the mode's methods.
bool chooseFullImageMode(const msf::tool::CommandLine& cli, const std::string& sequence_dir,
                         const msf::Sequence& sequence, Settings& settings) {
  if (settings.gt_switch && sequence.groundTruthDir().empty())
    throw msf::InvalidInputError("-gt: '" + sequence_dir +
                                 "' has no synthetic ground truth (no gt/depth_0 beside its sequences/, as msf_synth "
                                 "writes); without -gt it is evaluated by ring hold-out");
  const bool gt_mode = !settings.holdout_switch && !sequence.groundTruthDir().empty();
  if (settings.breakdown && gt_mode)
    throw msf::InvalidInputError("-breakdown splits the ring hold-out's ground truth; full-image mode has its own "
                                 "regions (add -holdout to evaluate '" + sequence_dir + "' by ring hold-out)");
  if (!cli.given("-methods"))
    settings.methods_text = gt_mode ? kGroundTruthMethods : methodNames();
  if (!settings.bounds_text.empty() && gt_mode)
    throw msf::InvalidInputError("-bounds is a ring hold-out option (add -holdout to evaluate '" + sequence_dir +
                                 "' by ring hold-out)");
  if (!settings.csv_path.empty() && msf::fileExtension(settings.csv_path) != ".csv")
    throw msf::InvalidInputError("-csv '" + settings.csv_path + "' must end in .csv");
  msf::tool::requireNewOutputs({settings.csv_path}, settings.overwrite);
  return gt_mode;
}

/// The methods -methods names, each also added to `evaluation`, and the bounds of -bounds.
NamedMethods addMethods(const Settings& settings, const msf::ConfigFile& config_file,
                        msf::HoldoutEvaluation& evaluation) {
  NamedMethods methods;
  const auto names = split(settings.methods_text);
  if (names.empty())
    throw msf::InvalidInputError("-methods is empty; known methods: " + methodNames());
  for (const auto& name : names) {
    const MethodEntry* entry = nullptr;
    for (const auto& m : methodTable())
      if (name == m.name)
        entry = &m;
    if (!entry)
      throw msf::InvalidInputError("unknown method '" + name + "'; known methods: " + methodNames());
    methods.emplace_back(name, entry->make(config_file));
    evaluation.addMethod(name, methods.back().second);
  }
  if (!settings.bounds_text.empty()) {
    const auto pair = split(settings.bounds_text);
    if (pair.size() != 2)
      throw msf::InvalidInputError("-bounds needs two methods separated by a comma, got '" + settings.bounds_text +
                                   "'");
    evaluation.addFusionBounds(pair[0], pair[1]);
  }
  return methods;
}

/// Full-image mode: the rows of all, background and foreground pixels of each method.
void reportFullImage(const msf::Sequence& sequence, const std::vector<std::size_t>& frames,
                     const NamedMethods& methods, const msf::D1Threshold& d1, const Settings& settings) {
  pcl::StopWatch watch;
  const auto results = runFullImage(sequence, frames, methods, d1);
  const double ms = watch.getTime();
  std::printf("%s", formatRegionTable(results).c_str());
  std::fflush(stdout);
  if (!settings.csv_path.empty())
    writeRegionCsv(settings.csv_path, results);
  msf::tool::printDone(ms, results.empty() ? 0 : results.front().region[0].metrics.gt_pixels, "held-out pixels");
}

/// Ring hold-out: a row per method, and with -breakdown its rows by visibility and depth.
void reportHoldout(const msf::Sequence& sequence, const std::vector<std::size_t>& frames,
                   msf::HoldoutEvaluation& evaluation, const Settings& settings) {
  pcl::StopWatch watch;
  const auto results = evaluation.run(sequence, frames);
  const double ms = watch.getTime();
  std::printf("%s", msf::formatHoldoutTable(results).c_str());
  if (settings.breakdown)
    std::printf("\n%s", msf::formatHoldoutBreakdown(results).c_str());
  std::vector<std::pair<std::string, msf::FusionLoss>> losses;
  for (const auto& r : results)
    if (r.lost_to_bound)
      losses.emplace_back(r.method, *r.lost_to_bound);
  if (!losses.empty()) {
    const auto inputs = split(settings.bounds_text);
    std::printf("\n%s", msf::formatFusionLoss(losses, inputs[0], inputs[1]).c_str());
  }
  std::fflush(stdout);
  if (!settings.csv_path.empty())
    msf::writeHoldoutCsv(settings.csv_path, results);
  msf::tool::printDone(ms, results.empty() ? 0 : results.front().metrics.gt_pixels, "held-out pixels");
}

int run(const msf::tool::CommandLine& cli, const msf::tool::Arguments& positional, Settings& settings) {
  if (positional.size() != 1)
    throw msf::InvalidInputError("expected one <sequence_dir> (see -h)");
  if (settings.gt_switch && settings.holdout_switch)
    throw msf::InvalidInputError("-gt and -holdout exclude each other");
  const msf::Sequence sequence(positional[0]);
  const bool gt_mode = chooseFullImageMode(cli, positional[0], sequence, settings);

  const msf::ConfigFile config_file =
      settings.config_path.empty() ? msf::ConfigFile() : msf::openConfigFile(settings.config_path);
  msf::HoldoutConfig config;
  config_file.read(config.rings);
  config_file.read(config.projection);
  msf::HoldoutEvaluation evaluation(config);
  evaluation.setBreakdown(settings.breakdown);
  const NamedMethods methods = addMethods(settings, config_file, evaluation);

  const auto frames = sequence.indices(msf::FrameRange::parse(settings.frames_text));
  print_highlight("Evaluating ");
  print_value("%zu frames ", frames.size());
  print_info("of %s, %zu methods%s\n", sequence.directory().c_str(), methods.size(),
             gt_mode ? ", full image against synthetic ground truth" : ", ring hold-out");
  if (gt_mode)
    reportFullImage(sequence, frames, methods, config.d1, settings);
  else
    reportHoldout(sequence, frames, evaluation, settings);
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::tool::CommandLine cli(
      "msf_holdout", "<sequence_dir> [options]",
      "Ring hold-out (evaluation protocol 2): rings with id % 4 == 2 of each scan are ground truth in camera 0, the "
      "others are the only LiDAR input. Prints one row per method: coverage, D1 with a missing estimate counted as "
      "bad, D1 over estimates, mean disparity error, depth MAE, RMSE, iMAE, iRMSE (1/km) and the median time of a "
      "method per frame (projection included).\n"
      "Full-image mode (protocol 3), automatic when the sequence has synthetic ground truth (gt/, as msf_synth "
      "writes): the whole scan is the LiDAR input, every pixel of gt/depth_0 is ground truth, and each method has "
      "rows for all, background and foreground pixels (gt/obj_map_0).");
  cli.value("-frames", "a:b", settings.frames_text, "frames to use (default: all)")
      .flag("-gt", settings.gt_switch, "full-image mode; an error when the sequence has no gt/")
      .flag("-holdout", settings.holdout_switch, "ring hold-out even when the sequence has gt/")
      .value("-methods", "a,b,..", settings.methods_text, methodsHelp())
      .value("-config", "FILE", settings.config_path,
             "YAML config (sections projection, rings, interpolation, ip_basic, stereo, fusion)")
      .value("-bounds", "A,B", settings.bounds_text,
             "ring hold-out: also the rows a per-pixel fusion of methods A and B cannot beat, found with the ground "
             "truth: bound_select (per pixel the input nearer the truth: the least MAE of choosing one) and "
             "bound_blend (the value between the two nearest the truth: the least error of a weighted mean); e.g. "
             "-bounds interpolated,sgbm_guided; and, for every other method, the pixels it lost to bound_select "
             "(bad where an input is right) by which input was right and what it gave there, and, where both "
             "inputs have a depth and one is right, how often giving each was right and wrong")
      .value("-csv", "FILE", settings.csv_path, "also write the rows as CSV")
      .flag("-breakdown", settings.breakdown,
            "ring hold-out: also each method's rows for the ground truth that camera 0 sees (visible) and cannot see "
            "(hidden: an input return within 1 px in front of it), and for the depth bands < 20, 20-40, >= 40 m; "
            "'MAE part' adds up to the MAE; and the share of estimates off by >= 10 m (another surface) with their "
            "part of it")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 1,
                 [&](const msf::tool::Arguments& positional) { return run(cli, positional, settings); });
}
