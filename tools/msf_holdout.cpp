// Evaluation protocol 2 (DESIGN.md): ring hold-out on real KITTI scans. One row per
// method: the table a user compares depth methods with.
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/evaluation/holdout.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/io/sequence.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/stereo/sgbm_stereo.h>

#include <pcl/common/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <functional>
#include <memory>
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
  msf::ProjectionConfig projection;
  projection.read(file.section("projection"));
  msf::InterpolationConfig interpolation;
  interpolation.read(file.section("interpolation"));
  msf::IpBasicConfig ip_basic;
  ip_basic.read(file.section("ip_basic"));
  std::shared_ptr<msf::LidarCompletion> completion; // made at the first frame, which has the calibration
  return [=](const msf::HoldoutInput& in) mutable {
    if (!completion)
      completion = std::make_shared<msf::LidarCompletion>(*in.calibration, method, projection, interpolation, ip_basic);
    cv::Mat depth;
    completion->computeDepth(*in.scan, depth);
    return depth;
  };
}

/// SGBM on the grey pair (section stereo); with `prior`, its search narrowed by the compound
/// interpolation of the input rings, whose time then counts too.
msf::HoldoutMethod stereo(const msf::ConfigFile& file, bool prior) {
  msf::SgbmConfig config;
  config.read(file.section("stereo"));
  auto completion = lidar(file, msf::CompletionMethod::Compound);
  auto sgbm = std::make_shared<msf::SgbmStereo>(config);
  return [=](const msf::HoldoutInput& in) {
    sgbm->setCalibration(*in.calibration);
    sgbm->setInputImages(in.left, in.right);
    sgbm->setDepthPrior(prior ? completion(in) : cv::Mat());
    sgbm->computeDisparity();
    return sgbm->getDepth();
  };
}

/// Paper steps 1-4: compound interpolation of the input rings, SGBM narrowed by it, and the
/// per-pixel fusion of the two (section fusion, its method forced to `method`).
msf::HoldoutMethod fused(const msf::ConfigFile& file, msf::FusionMethod method) {
  msf::ProjectionConfig projection;
  projection.read(file.section("projection"));
  msf::InterpolationConfig interpolation;
  interpolation.read(file.section("interpolation"));
  msf::SgbmConfig stereo_config;
  stereo_config.read(file.section("stereo"));
  msf::DepthFusionConfig fusion;
  fusion.read(file.section("fusion"));
  fusion.method = method;
  std::shared_ptr<msf::LidarCompletion> completion;
  auto sgbm = std::make_shared<msf::SgbmStereo>(stereo_config);
  auto fuser = std::make_shared<msf::DepthImageFusion>(fusion);
  return [=](const msf::HoldoutInput& in) mutable {
    if (!completion)
      completion = std::make_shared<msf::LidarCompletion>(*in.calibration, msf::CompletionMethod::Compound,
                                                          projection, interpolation);
    cv::Mat lidar_depth, distance, depth;
    completion->computeDepth(*in.scan, lidar_depth, &distance);
    sgbm->setCalibration(*in.calibration);
    sgbm->setInputImages(in.left, in.right);
    sgbm->setDepthPrior(lidar_depth);
    sgbm->computeDisparity();
    fuser->setCalibration(*in.calibration);
    fuser->fuse(lidar_depth, distance, sgbm->getDepth(), sgbm->getConfidence(), depth);
    return depth;
  };
}

/// Add a method here (name -> function of the frame input) to get its row in the table.
const std::vector<MethodEntry>& methodTable() {
  static const std::vector<MethodEntry> table{
      {"interpolated", "compound interpolation (section interpolation)",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Compound); }},
      {"linear", "the same slices, linear only",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Linear); }},
      {"cubic", "the same slices, zero-slope cubic only",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::Cubic); }},
      {"ipbasic", "IP-Basic fast (Ku et al. 2018, section ip_basic), same projection",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::IpBasicFast); }},
      {"ipbasic_multiscale", "IP-Basic multiscale, same projection",
       [](const msf::ConfigFile& f) { return lidar(f, msf::CompletionMethod::IpBasicMultiscale); }},
      {"sgbm", "OpenCV SGBM on the grey pair (section stereo), no LiDAR",
       [](const msf::ConfigFile& f) { return stereo(f, false); }},
      {"sgbm_prior", "the same, its search narrowed by the interpolated input rings",
       [](const msf::ConfigFile& f) { return stereo(f, true); }},
      {"fused_paper", "interpolated + sgbm_prior fused by eq. 6 (section fusion)",
       [](const msf::ConfigFile& f) { return fused(f, msf::FusionMethod::Paper); }},
      {"fused_uncertainty", "interpolated + sgbm_prior fused by inverse variance",
       [](const msf::ConfigFile& f) { return fused(f, msf::FusionMethod::Uncertainty); }},
  };
  return table;
}

std::string methodNames() {
  std::string names;
  for (const auto& m : methodTable())
    names += (names.empty() ? "" : ",") + std::string(m.name);
  return names;
}

void printHelp(const char* name) {
  print_error("Syntax is: %s <sequence_dir> [options]\n", name);
  print_info("  Ring hold-out (evaluation protocol 2): rings with id %% 4 == 2 of each scan are ground truth in\n"
             "  camera 0, the others are the only LiDAR input. Prints one row per method: coverage, D1 with a\n"
             "  missing estimate counted as bad, D1 over estimates, mean disparity error, depth MAE, RMSE, iMAE,\n"
             "  iRMSE (1/km) and the median time of a method per frame (projection included).\n");
  print_info("  where options are:\n");
  print_info("    -frames a:b      frames to use (default: all)\n");
  print_info("    -methods a,b,..  methods, in this order (default: all):\n");
  for (const auto& m : methodTable())
    print_info("                       %-19s %s\n", m.name, m.description);
  print_info("    -config FILE     YAML config (sections projection, rings, interpolation, ip_basic, stereo,\n"
             "                     fusion)\n");
  print_info("    -csv FILE        also write the rows as CSV\n");
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty())
      out.push_back(item);
  return out;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::run("msf_holdout", [&] {
    if (argc < 2 || msf::tool::wantsHelp(argc, argv)) {
      printHelp(argv[0]);
      return argc < 2 ? 1 : 0;
    }
    const std::vector<std::string> value_options{"-frames", "-methods", "-config", "-csv"};
    msf::tool::checkOptions(argc, argv, value_options, {});
    const auto positional = msf::tool::positionalArguments(argc, argv, value_options);
    if (positional.size() != 1)
      throw msf::InvalidInputError("expected one <sequence_dir> (see -h)");
    std::string frames_text = "0:", methods_text = methodNames(), config_path, csv_path;
    parse_argument(argc, argv, "-frames", frames_text);
    parse_argument(argc, argv, "-methods", methods_text);
    parse_argument(argc, argv, "-config", config_path);
    parse_argument(argc, argv, "-csv", csv_path);
    if (!csv_path.empty() && msf::fileExtension(csv_path) != ".csv")
      throw msf::InvalidInputError("-csv '" + csv_path + "' must end in .csv");

    const msf::ConfigFile config_file = config_path.empty() ? msf::ConfigFile() : msf::ConfigFile(config_path);
    msf::HoldoutConfig config;
    config.rings.read(config_file.section("rings"));
    config.projection.read(config_file.section("projection"));
    msf::HoldoutEvaluation evaluation(config);
    const auto names = split(methods_text);
    if (names.empty())
      throw msf::InvalidInputError("-methods is empty; known methods: " + methodNames());
    for (const auto& name : names) {
      const MethodEntry* entry = nullptr;
      for (const auto& m : methodTable())
        if (name == m.name)
          entry = &m;
      if (!entry)
        throw msf::InvalidInputError("unknown method '" + name + "'; known methods: " + methodNames());
      evaluation.addMethod(name, entry->make(config_file));
    }

    const msf::Sequence sequence(positional[0]);
    const auto frames = sequence.indices(msf::FrameRange::parse(frames_text));
    print_highlight("Evaluating ");
    print_value("%zu frames ", frames.size());
    print_info("of %s, %zu methods\n", sequence.directory().c_str(), names.size());
    pcl::StopWatch watch;
    const auto results = evaluation.run(sequence, frames);
    const double ms = watch.getTime();
    std::printf("%s", msf::formatHoldoutTable(results).c_str());
    std::fflush(stdout);
    if (!csv_path.empty())
      msf::writeHoldoutCsv(csv_path, results);
    msf::tool::printDone(ms, results.empty() ? 0 : results.front().metrics.gt_pixels);
    return 0;
  });
}
