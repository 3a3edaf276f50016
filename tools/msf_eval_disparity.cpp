// The KITTI 2015 devkit's disparity evaluation of one estimate: D1 (3 px and 5 %) for
// background, foreground and all pixels, the paper's eq. 8 mean absolute error, density.
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/evaluation/disparity_metrics.h>
#include <msf/io/image_io.h>

#include <opencv2/imgcodecs.hpp>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <cstdio>
#include <string>

using namespace pcl::console;

namespace {

void printHelp(const char* name) {
  print_error("Syntax is: %s <gt.png> <est.png> [options]\n", name);
  print_info("  KITTI 16-bit disparity PNGs (pixels x 256, 0 = none): D1 outliers (error > 3 px and > 5 %%),\n");
  print_info("  mean absolute error (eq. 8) and density, per region when an object map is given.\n");
  print_info("  where options are:\n");
  print_info("    -obj_map PATH     object map (0 = background, else foreground), e.g. KITTI obj_map/*.png\n");
  print_info("    -interpolate      fill missing estimates as the devkit does (background interpolation);\n");
  print_info("                      without it a missing estimate counts as bad in D1\n");
  print_info("    -abs_px X         absolute threshold in pixels (default 3)\n");
  print_info("    -rel X            relative threshold (default 0.05)\n");
}

void printRow(const char* name, const msf::DisparityRegionErrors& r) {
  std::printf("%-11s %8.2f %%  %8.2f %%  %8.2f %%  %8.3f  %9zu  %9zu\n", name, 100.0 * r.d1(), 100.0 * r.d1Estimated(),
              100.0 * r.density(), r.meanAbsError(), r.bad, r.gt_pixels);
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::run("msf_eval_disparity", [&] {
    if (argc < 3 || msf::tool::wantsHelp(argc, argv)) {
      printHelp(argv[0]);
      return msf::tool::wantsHelp(argc, argv) ? 0 : 1;
    }
    const std::vector<std::string> value_options{"-obj_map", "-abs_px", "-rel"};
    msf::tool::checkOptions(argc, argv, value_options, {"-interpolate"});
    const auto files = msf::tool::positionalArguments(argc, argv, value_options);
    if (files.size() != 2)
      throw msf::InvalidInputError("expected <gt.png> <est.png> (see -h)");
    msf::DisparityEvalOptions options;
    options.interpolate_background = find_switch(argc, argv, "-interpolate");
    parse_argument(argc, argv, "-abs_px", options.abs_threshold_px);
    parse_argument(argc, argv, "-rel", options.rel_threshold);
    if (!(options.abs_threshold_px >= 0.f) || !(options.rel_threshold >= 0.f))
      throw msf::InvalidInputError("-abs_px and -rel must be >= 0");
    std::string obj_map_path;
    parse_argument(argc, argv, "-obj_map", obj_map_path);

    const cv::Mat gt = msf::readKittiDisparityPng(files[0]);
    const cv::Mat est = msf::readKittiDisparityPng(files[1]);
    if (est.size() != gt.size())
      throw msf::InvalidInputError("estimate '" + files[1] + "' is " + std::to_string(est.cols) + "x" +
                                   std::to_string(est.rows) + " but ground truth '" + files[0] + "' is " +
                                   std::to_string(gt.cols) + "x" + std::to_string(gt.rows));
    cv::Mat obj_map;
    if (!obj_map_path.empty()) {
      obj_map = msf::readImage(obj_map_path, cv::IMREAD_UNCHANGED);
      if (obj_map.channels() != 1)
        throw msf::InvalidInputError("object map '" + obj_map_path + "' must be a single-channel image");
      if (obj_map.size() != gt.size())
        throw msf::InvalidInputError("object map '" + obj_map_path + "' is " + std::to_string(obj_map.cols) + "x" +
                                     std::to_string(obj_map.rows) + " but ground truth '" + files[0] + "' is " +
                                     std::to_string(gt.cols) + "x" + std::to_string(gt.rows));
    }
    const msf::DisparityEvaluation e = msf::evaluateDisparity(gt, est, obj_map, options);

    std::printf("%-11s %10s  %10s  %10s  %8s  %9s  %9s\n", "region", "D1", "D1 (est.)", "density", "MAE px",
                "bad", "gt pixels");
    if (e.has_object_map) {
      printRow("background", e.background);
      printRow("foreground", e.foreground);
    }
    printRow("all", e.all);
    std::printf("(D1: error > %g px and > %g %% of the true disparity; %s)\n", options.abs_threshold_px,
                100.0 * options.rel_threshold,
                options.interpolate_background ? "missing estimates interpolated as the devkit"
                                               : "missing estimates count as bad");
    return 0;
  });
}
