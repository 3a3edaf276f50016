// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "test_support.h"

#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/lambda_study.h>

#include <fstream>
#include <sstream>

using namespace msf;

namespace {
LambdaStudy::Config smallStudy() {
  LambdaStudy::Config c;
  c.frames = 4;
  c.width = 200;
  c.height = 150;
  c.focal_px = 190;
  return c;
}
} // namespace

TEST(LambdaStudy, LambdaHelpsAtHighNoiseAndHurtsAtNone) {
  // The paper's finding (Fig. 5): small lambda is best on clean depth, larger lambda on noisy depth.
  const LambdaStudy study(smallStudy());
  const double clean_plain = study.run(0, 0).mae_mm, clean_smooth = study.run(0, 5).mae_mm;
  const double noisy_plain = study.run(80, 0).mae_mm, noisy_smooth = study.run(80, 5).mae_mm;
  std::printf("  sigma 0: lambda 0 %.2f mm, lambda 5 %.2f mm; sigma 80 mm: lambda 0 %.2f mm, lambda 5 %.2f mm\n",
              clean_plain, clean_smooth, noisy_plain, noisy_smooth);
  EXPECT_LT(clean_plain, 0.1 * 50.0); // exact depth: within a tenth of a voxel
  EXPECT_LT(clean_plain, clean_smooth);
  EXPECT_LT(noisy_smooth, noisy_plain);
}

TEST(LambdaStudy, ConfigIsReadAndChecked) {
  test::TempDir dir;
  std::ofstream(dir.file("study.yaml")) << "%YAML:1.0\nlambda_study:\n  noise_mm: [0, 10]\n  lambdas: [0, 2.5]\n  frames: 3\n";
  LambdaStudy::Config c;
  ConfigFile(dir.file("study.yaml")).read(c);
  EXPECT_EQ(c.noise_mm, (std::vector<double>{0, 10}));
  EXPECT_EQ(c.lambdas, (std::vector<double>{0, 2.5}));
  EXPECT_EQ(c.frames, 3);
  std::ostringstream printed;
  printConfig(printed, c);
  EXPECT_NE(printed.str().find("lambdas: [0, 2.5]"), std::string::npos) << printed.str();
  c.frames = 0;
  EXPECT_THROW(LambdaStudy{c}, ConfigError);
  c = LambdaStudy::Config();
  c.lambdas = {-1};
  EXPECT_THROW(LambdaStudy{c}, ConfigError);
}

TEST(LambdaStudy, ToolWritesTheTableAndThePlot) {
  test::TempDir dir;
  std::ofstream(dir.file("study.yaml")) << "%YAML:1.0\nlambda_study:\n  noise_mm: [0, 40]\n  lambdas: [0, 5]\n"
                                           "  frames: 2\n  width: 160\n  height: 120\n  focal_px: 150\n";
  const std::string out = dir.file("out");
  auto r = test::runTool("msf_lambda_study", "-o " + out + " -config " + dir.file("study.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream csv(out + "/lambda_study.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "noise_mm,lambda,mae_mm,vertices,integrate_ms_per_frame,sweeps_per_frame");
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    const double sweeps = std::stod(line.substr(line.rfind(',') + 1));
    EXPECT_EQ(sweeps, line.find(",5.00,") != std::string::npos ? 1.0 : 0.0) << line; // one per frame, none at 0
  }
  EXPECT_EQ(rows, 4);
  EXPECT_TRUE(test::fileExists(out + "/lambda_study.png"));
  // The paper's solve: eq. 7 to its minimizer, many sweeps a frame.
  r = test::runTool("msf_lambda_study", "-o " + out + " -config " + dir.file("study.yaml") + " -solve argmin");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream argmin(out + "/lambda_study.csv");
  std::getline(argmin, line);
  while (std::getline(argmin, line)) {
    if (line.find(",5.00,") != std::string::npos) {
      EXPECT_GT(std::stod(line.substr(line.rfind(',') + 1)), 5.0) << line;
    }
  }
  r = test::runTool("msf_lambda_study", "-o " + out + " -solve exact");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-solve"), std::string::npos) << r.err;
  r = test::runTool("msf_lambda_study", "-o " + dir.file("missing/out"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_lambda_study: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
}
