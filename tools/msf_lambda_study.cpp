// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_lambda_study: paper Fig. 5 — surface error of the regularized TSDF fusion (eq. 7)
// against lambda and depth noise on a synthetic scene with exact ground truth.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/tool.h>
#include <msf/io/image_io.h>
#include <msf/reconstruction/lambda_study.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

/// The study of `config` into `out_dir`: the table on the console, the CSV and the figure.
int run(const msf::LambdaStudy::Config& config, const std::string& out_dir) {
  const msf::LambdaStudy study(config); // validates: a bad value leaves no output folder
  msf::OutputFolder output(out_dir, "msf_lambda_study");
  msf::printConfig(std::cout, config);

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
  msf::LambdaStudy::writeCsv(output.dir() + "/lambda_study.csv", cells);
  msf::writeImage(output.dir() + "/lambda_study.png", figure);
  output.commit();
  print_info("Wrote ");
  print_value("%s", csv.c_str());
  print_info(" and ");
  print_value("%s ", png.c_str());
  msf::tool::printDone(tt.toc(), cells.size(), "cells");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  std::string out_dir;
  msf::LambdaStudy::Config config;
  msf::tool::CommandLine cli(
      "msf_lambda_study", "-o DIR [options]",
      "Fuses noisy depth of a synthetic scene (smooth parts, edges, sharp boundaries) with each lambda of eq. 7 and "
      "writes DIR/lambda_study.csv and DIR/lambda_study.png (paper Fig. 5).");
  cli.value("-o", "DIR", out_dir, "output folder: absent, empty, or one an earlier study wrote (replaced)")
      .value("-config", "FILE", [&](const std::string& path) { msf::readConfigSection(path, config); },
             "YAML with a section lambda_study (noise_mm, lambdas, frames, ...)")
      .value("-frames", "N", config.frames, "frames fused per cell (default {default})")
      .value("-voxel", "M", config.voxel_size_m, "voxel size in metres (default {default})")
      .value("-trunc", "M", config.truncation_m, "truncation in metres (default {default})")
      .value("-sweeps", "N", config.sweeps, "Gauss-Seidel sweeps per frame (default {default})")
      .value("-solve", "S",
             [&](const std::string& solve) {
               try {
                 config.solve = msf::parseSolve(solve);
               } catch (const msf::ConfigError&) {
                 throw msf::InvalidInputError("-solve must be sweeps or argmin, not '" + solve + "'");
               }
             },
             std::string("sweeps: -sweeps per frame, warm-started | argmin: eq. 7 solved to its minimizer every frame, "
                         "as the paper states it (default ") + msf::toString(config.solve) + ")");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    if (!positional.empty())
      throw msf::InvalidInputError("unexpected argument '" + positional[0] + "' (see -h)");
    if (!cli.given("-o")) {
      cli.printHelp(argv[0]);
      throw msf::InvalidInputError("need -o DIR");
    }
    return run(config, out_dir);
  });
}
