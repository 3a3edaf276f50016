// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Evaluation protocol 3 in the tools: msf_holdout in full-image mode on a synthetic sequence
// (rows all / background / foreground) and msf_eval_disparity over folders.
#include <msf/io/image_io.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/synthetic_generator.h>

#include "test_support.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// A 2-frame synthetic street, generated once per test process.
class SyntheticGtTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<msf::test::TempDir>();
    msf::synthetic::SyntheticConfig config;
    config.frames = 2;
    msf::synthetic::SyntheticGenerator(config).writeDataset(dataset());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string dataset() { return dir_->file("street"); }
  static std::string gtDir() { return dataset() + "/gt"; }
  static std::unique_ptr<msf::test::TempDir> dir_;
};
std::unique_ptr<msf::test::TempDir> SyntheticGtTest::dir_;

std::string quote(const std::string& s) { return "'" + s + "'"; }

/// One row of msf_holdout's full-image table: method, region, then the numbers
/// (coverage, D1 all %, D1 est %, disparity MAE px, MAE m, RMSE m, iMAE, iRMSE, ms).
struct Row {
  double coverage = -1, d1_all = -1, d1_est = -1, disp_mae = -1, mae = -1, rmse = -1;
};

std::map<std::string, Row> parseRegionTable(const std::string& out) {
  std::map<std::string, Row> rows;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string method, region, d1_all, d1_est, disp_mae;
    Row r;
    if (!(in >> method >> region >> r.coverage >> d1_all >> d1_est >> disp_mae >> r.mae >> r.rmse))
      continue;
    r.d1_all = std::stod(d1_all);   // "12.34%"
    r.d1_est = std::stod(d1_est);
    r.disp_mae = std::stod(disp_mae); // "1.234px"
    rows[method + "/" + region] = r;
  }
  return rows;
}

TEST_F(SyntheticGtTest, HoldoutFullImageTableHasRegionsAndFusionBeatsSgbm) {
  const std::string csv = dir_->file("table.csv");
  const auto r = msf::test::runTool("msf_holdout", quote(dataset()) + " -frames 0:1 -csv " + quote(csv));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("region"), std::string::npos) << r.out;
  const auto rows = parseRegionTable(r.out);
  for (const char* method : {"sgbm", "interpolated", "fused_uncertainty", "fused_paper", "paper", "ipbasic_multiscale"})
    for (const char* region : {"all", "background", "foreground"}) {
      const std::string key = std::string(method) + "/" + region;
      ASSERT_TRUE(rows.count(key)) << "no row " << key << " in\n" << r.out;
      const Row& row = rows.at(key);
      EXPECT_GE(row.coverage, 0.0) << key;
      EXPECT_LE(row.coverage, 1.0) << key;
      EXPECT_GE(row.d1_all, row.d1_est * row.coverage - 1e-6) << key;
      EXPECT_GE(row.d1_all, 0.0) << key;
      EXPECT_LE(row.d1_all, 100.0) << key;
      EXPECT_GE(row.rmse, row.mae) << key;
    }
  // Full image: the interpolated LiDAR covers most of the image, SGBM less; fusion beats SGBM.
  EXPECT_GT(rows.at("interpolated/all").coverage, 0.5);
  EXPECT_LT(rows.at("fused_uncertainty/all").d1_all, rows.at("sgbm/all").d1_all) << r.out;
  EXPECT_LT(rows.at("fused_paper/all").d1_all, rows.at("sgbm/all").d1_all) << r.out;
  ASSERT_TRUE(msf::test::fileExists(csv));
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("method,region,", 0), 0u) << header;
}

TEST_F(SyntheticGtTest, HoldoutGtSwitchWithoutGroundTruthIsAnError) {
  // The same sequence without its gt/ folder.
  msf::test::TempDir copy;
  fs::copy(dataset() + "/sequences", copy.file("sequences"), fs::copy_options::recursive);
  const auto r = msf::test::runTool("msf_holdout", quote(copy.path()) + " -gt -frames 0:0 -methods interpolated");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_holdout: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ground truth"), std::string::npos) << r.err;
  // -gt and -holdout together are refused too.
  const auto both = msf::test::runTool("msf_holdout", quote(dataset()) + " -gt -holdout");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.err.find("msf_holdout: error:"), std::string::npos) << both.err;
  // -bounds belongs to the ring hold-out, which names the way to it.
  const auto bounds = msf::test::runTool("msf_holdout", quote(dataset()) + " -bounds interpolated,sgbm");
  EXPECT_NE(bounds.exit_code, 0);
  EXPECT_NE(bounds.err.find("-bounds is a ring hold-out option"), std::string::npos) << bounds.err;
}

TEST_F(SyntheticGtTest, EvalDisparityFoldersGroundTruthAgainstItself) {
  const std::string disp = gtDir() + "/disp_0";
  const auto r = msf::test::runTool("msf_eval_disparity", quote(disp) + " " + quote(disp));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("2 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("obj_map_0"), std::string::npos) << r.out; // the sibling object maps were found
  for (const char* region : {"background", "foreground", "all"}) {
    std::istringstream lines(r.out);
    std::string line;
    bool found = false;
    while (std::getline(lines, line)) {
      std::istringstream in(line);
      std::string name, pct;
      double d1 = -1, d1_est = -1, density = -1;
      if (!(in >> name) || name != region)
        continue;
      in >> d1 >> pct >> d1_est >> pct >> density;
      found = true;
      EXPECT_DOUBLE_EQ(d1, 0.0) << line;
      EXPECT_DOUBLE_EQ(density, 100.0) << line;
    }
    EXPECT_TRUE(found) << "no row " << region << " in\n" << r.out;
  }
}

TEST_F(SyntheticGtTest, EvalDisparityFoldersSplitByObjectMap) {
  // Estimate = ground truth on the background, nothing on the foreground: background D1 0,
  // foreground D1 100 % (missing counts as bad), summed over both frames.
  const msf::synthetic::GroundTruth gt(dataset());
  ASSERT_EQ(gt.size(), 2u);
  msf::test::TempDir est;
  std::size_t foreground = 0;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    cv::Mat d = gt.disparity(i).clone();
    const cv::Mat fg = gt.split(i).foreground;
    foreground += static_cast<std::size_t>(cv::countNonZero(fg));
    d.setTo(0.f, fg);
    msf::writeKittiDisparityPng(est.file(gt.frameName(i) + ".png"), d);
  }
  ASSERT_GT(foreground, 0u);
  const auto r = msf::test::runTool("msf_eval_disparity", quote(gtDir() + "/disp_0") + " " + quote(est.path()));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  std::istringstream lines(r.out);
  std::string line;
  std::map<std::string, double> d1;
  std::map<std::string, std::size_t> gt_pixels;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string name, pct;
    double v = -1, d1_est, density, mae;
    std::size_t bad, pixels;
    if (in >> name >> v >> pct >> d1_est >> pct >> density >> pct >> mae >> bad >> pixels) {
      d1[name] = v;
      gt_pixels[name] = pixels;
    }
  }
  ASSERT_TRUE(d1.count("background") && d1.count("foreground") && d1.count("all")) << r.out;
  EXPECT_DOUBLE_EQ(d1["background"], 0.0);
  EXPECT_DOUBLE_EQ(d1["foreground"], 100.0);
  EXPECT_EQ(gt_pixels["foreground"], foreground);
  EXPECT_EQ(gt_pixels["all"], gt_pixels["background"] + gt_pixels["foreground"]);
}

TEST_F(SyntheticGtTest, EvalDisparityFoldersMissingCounterpartIsAnError) {
  msf::test::TempDir est;
  const msf::synthetic::GroundTruth gt(dataset());
  msf::writeKittiDisparityPng(est.file(gt.frameName(0) + ".png"), gt.disparity(0));
  msf::writeKittiDisparityPng(est.file("000099.png"), gt.disparity(0));
  const auto r = msf::test::runTool("msf_eval_disparity", quote(gtDir() + "/disp_0") + " " + quote(est.path()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_eval_disparity: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("000099.png"), std::string::npos) << r.err;
  // A folder against a file is refused as well.
  const auto mixed = msf::test::runTool("msf_eval_disparity",
                                        quote(gtDir() + "/disp_0") + " " + quote(est.file("000099.png")));
  EXPECT_NE(mixed.exit_code, 0);
  EXPECT_NE(mixed.err.find("msf_eval_disparity: error:"), std::string::npos) << mixed.err;
}

} // namespace
