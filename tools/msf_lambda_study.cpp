// msf_lambda_study: paper Fig. 5 — surface error of the regularized TSDF fusion (eq. 7)
// against lambda and depth noise on a synthetic scene with exact ground truth.
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/image_io.h>
#include <msf/reconstruction/lambda_study.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

const std::vector<std::string> kValueOptions = {"-o", "-config", "-frames", "-voxel", "-trunc", "-sweeps", "-solve"};

void printHelp(const char* name) {
  print_error("Syntax is: %s -o DIR [options]\n", name);
  print_info("  Fuses noisy depth of a synthetic scene (smooth parts, edges, sharp boundaries) with each\n"
             "  lambda of eq. 7 and writes DIR/lambda_study.csv and DIR/lambda_study.png (paper Fig. 5).\n"
             "  Options:\n");
  print_info("    -config FILE   YAML with a section lambda_study (noise_mm, lambdas, frames, ...)\n");
  print_info("    -frames N      frames fused per cell (default "); print_value("10"); print_info(")\n");
  print_info("    -voxel M       voxel size in metres (default "); print_value("0.05"); print_info(")\n");
  print_info("    -trunc M       truncation in metres (default "); print_value("0.25"); print_info(")\n");
  print_info("    -sweeps N      Gauss-Seidel sweeps per frame (default "); print_value("1"); print_info(")\n");
  print_info("    -solve S       sweeps: -sweeps per frame, warm-started | argmin: eq. 7 solved to its minimizer\n"
             "                   every frame, as the paper states it (default "); print_value("sweeps"); print_info(")\n");
}

int run(int argc, char** argv) {
  msf::tool::checkOptions(argc, argv, kValueOptions, {});
  if (!msf::tool::positionalArguments(argc, argv, kValueOptions).empty())
    throw msf::InvalidInputError("unexpected argument '" + msf::tool::positionalArguments(argc, argv, kValueOptions)[0] +
                                 "' (see -h)");
  std::string out_dir;
  if (msf::tool::parseArgument(argc, argv, "-o", out_dir) < 0) {
    printHelp(argv[0]);
    throw msf::InvalidInputError("need -o DIR");
  }
  msf::LambdaStudy::Config config;
  std::string config_path;
  if (msf::tool::parseArgument(argc, argv, "-config", config_path) >= 0)
    msf::readConfigSection(config_path, "lambda_study", config);
  msf::tool::parseArgument(argc, argv, "-frames", config.frames);
  msf::tool::parseArgument(argc, argv, "-voxel", config.voxel_size_m);
  msf::tool::parseArgument(argc, argv, "-trunc", config.truncation_m);
  msf::tool::parseArgument(argc, argv, "-sweeps", config.sweeps);
  std::string solve = msf::toString(config.solve);
  msf::tool::parseArgument(argc, argv, "-solve", solve);
  try {
    config.solve = msf::parseSolve(solve);
  } catch (const msf::ConfigError&) {
    throw msf::InvalidInputError("-solve must be sweeps or argmin, not '" + solve + "'");
  }
  const msf::LambdaStudy study(config); // validates: a bad value leaves no output folder
  msf::ensureOutputDirectory(out_dir);
  config.print(std::cout);

  std::vector<msf::LambdaStudy::Cell> cells;
  TicToc tt;
  tt.tic();
  std::printf("%10s", "sigma\\lambda");
  for (const double l : config.lambdas)
    std::printf("%9g", l);
  std::printf("   (mean absolute surface error, mm)\n");
  for (const double s : config.noise_mm) {
    std::printf("%7g mm  ", s);
    double best = INFINITY, best_lambda = 0;
    for (const double l : config.lambdas) {
      cells.push_back(study.run(s, l));
      std::printf("%9.2f", cells.back().mae_mm);
      std::fflush(stdout);
      if (cells.back().mae_mm < best) {
        best = cells.back().mae_mm;
        best_lambda = l;
      }
    }
    std::printf("   best lambda %g\n", best_lambda);
  }
  const std::string csv = out_dir + "/lambda_study.csv", png = out_dir + "/lambda_study.png";
  const cv::Mat figure = msf::LambdaStudy::plot(cells);
  msf::LambdaStudy::writeCsv(csv, cells);
  msf::writeImage(png, figure);
  print_info("Wrote ");
  print_value("%s", csv.c_str());
  print_info(" and ");
  print_value("%s ", png.c_str());
  msf::tool::printDone(tt.toc(), cells.size());
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_lambda_study", 2, printHelp, [&] { return run(argc, argv); });
}
