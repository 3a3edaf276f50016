// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The paper as published, as a configuration: config/paper.yaml is
// PipelineConfig::paper(), and its rows on the shared KITTI frames are the ones docs/paper.md
// shows (the table between its test:paper_rows markers is this test's oracle).
#include <msf/common/exceptions.h>
#include <msf/pipeline/pipeline_config.h>

#include "test_support.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string printed(const msf::PipelineConfig& c) {
  std::ostringstream out;
  c.print(out);
  return out.str();
}

TEST(PaperConfig, TheFileIsTheConfigurationInCode) {
  const msf::PipelineConfig file = msf::PipelineConfig::load(msf::test::sourceDir() + "/config/paper.yaml");
  EXPECT_EQ(printed(file), printed(msf::PipelineConfig::paper()));
}

TEST(PaperConfig, EveryAdditionIsOff) {
  const msf::PipelineConfig c = msf::PipelineConfig::paper();
  EXPECT_FALSE(c.interpolation.slice.inverse_depth);
  EXPECT_FALSE(c.interpolation.slice.edge_test);
  EXPECT_EQ(c.interpolation.slice.interpolant, msf::SliceInterpolant::Compound);
  EXPECT_EQ(c.interpolation.slice.cubic_alpha, 2.f);
  EXPECT_EQ(c.interpolation.slice.cubic_beta, 3.f);
  EXPECT_EQ(c.interpolation.column_seed_gap_px, 0); // rows and columns independent
  EXPECT_TRUE(c.interpolation.gaussian);
  EXPECT_EQ(c.stereo.engine, "opencv");
  EXPECT_EQ(c.stereo.mode, "sgbm_3way");
  EXPECT_EQ(c.stereo.unguided_mode, "sgbm_3way");
  EXPECT_FALSE(c.stereo.lidarGuidance());
  EXPECT_FALSE(c.stereo.prior_search_range);
  EXPECT_FALSE(c.scheduling.stereo_prior);
  EXPECT_EQ(c.fusion.method, msf::FusionMethod::Paper);
  EXPECT_EQ(c.fusion.paper_weights, msf::PaperWeights::AsWritten);
  EXPECT_FALSE(c.fusion.edge_support);
  EXPECT_EQ(c.integrator.lambda, 5.0);
  EXPECT_EQ(c.integrator.solve, msf::TsdfIntegrator::Solve::Argmin);
  EXPECT_EQ(c.integrator.signed_distance, msf::TsdfIntegrator::SignedDistance::Projective);
  EXPECT_FALSE(c.integrator.space_carving);
  EXPECT_FALSE(c.integrator.sky_carving);
  EXPECT_FALSE(c.integrator.far_carving);
  EXPECT_FALSE(c.integrator.silhouette_band);
  // The project's own defaults keep every addition.
  const msf::PipelineConfig ours;
  EXPECT_TRUE(ours.interpolation.slice.inverse_depth && ours.interpolation.slice.edge_test &&
              ours.fusion.edge_support && ours.stereo.lidarGuidance() && ours.integrator.silhouette_band &&
              ours.integrator.sky_carving && ours.integrator.far_carving);
  EXPECT_EQ(ours.stereo.mode, "sgbm");
  EXPECT_EQ(ours.fusion.paper_weights, msf::PaperWeights::Relative);
  EXPECT_EQ(ours.integrator.solve, msf::TsdfIntegrator::Solve::Sweeps);
}

TEST(PaperConfig, ABadValueOfANewKeyIsNamed) {
  msf::test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"interpolation:\n  edge_test: sometimes\n", "interpolation.edge_test"},
      {"fusion:\n  paper_weights: literal\n", "fusion.paper_weights"},
      {"tsdf_integrator:\n  solve: exact\n", "tsdf_integrator.solve"},
      {"tsdf_integrator:\n  silhouette_band: sometimes\n", "tsdf_integrator.silhouette_band"},
      {"tsdf_integrator:\n  argmin_tolerance_m: -1\n", "tsdf_integrator.argmin_tolerance_m"},
      {"tsdf_integrator:\n  argmin_max_sweeps: 0\n", "tsdf_integrator.argmin_max_sweeps"}};
  for (const auto& [yaml, key] : cases) {
    std::ofstream(dir.file("bad.yaml")) << "%YAML:1.0\n" << yaml;
    try {
      msf::PipelineConfig::load(dir.file("bad.yaml"));
      ADD_FAILURE() << yaml << " was accepted";
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

/// One row of docs/paper.md's tested table.
struct DocumentedRow {
  std::string dataset, frames, method;
  double coverage = 0, d1_pct = 0, mae_m = 0;
};

std::vector<DocumentedRow> documentedRows() {
  std::ifstream in(msf::test::sourceDir() + "/docs/paper.md");
  std::string line;
  bool inside = false;
  std::vector<DocumentedRow> rows;
  while (std::getline(in, line)) {
    if (line.find("<!-- test:paper_rows:begin") != std::string::npos)
      inside = true;
    else if (line.find("<!-- test:paper_rows:end") != std::string::npos)
      break;
    else if (inside && line.rfind("| ", 0) == 0 && line.find("---") == std::string::npos &&
             line.find("dataset") == std::string::npos) {
      // | dataset | frames | method | coverage | D1 % | MAE m |
      std::vector<std::string> cells;
      std::stringstream ss(line.substr(1));
      std::string cell;
      while (std::getline(ss, cell, '|')) {
        const auto a = cell.find_first_not_of(" `"), b = cell.find_last_not_of(" `%m");
        cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
      }
      if (cells.size() < 6)
        continue;
      rows.push_back({cells[0], cells[1], cells[2], std::stod(cells[3]), std::stod(cells[4]), std::stod(cells[5])});
    }
  }
  return rows;
}

/// msf_holdout's CSV rows by method: coverage, d1_all, mae_m.
std::map<std::string, std::vector<double>> holdoutRows(const std::string& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line); // method,frames,gt_pixels,estimated,coverage,d1_all,d1_estimated,disparity_mae_px,mae_m,...
  std::map<std::string, std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ','))
      cells.push_back(cell);
    if (cells.size() > 8)
      rows[cells[0]] = {std::stod(cells[4]), std::stod(cells[5]), std::stod(cells[8])};
  }
  return rows;
}

TEST(PaperConfig, RowsOnTheSharedFramesAreTheDocumentedOnes) {
  MSF_REQUIRE_KITTI();
  const auto rows = documentedRows();
  ASSERT_GE(rows.size(), 4u) << "no table between the test:paper_rows markers of docs/paper.md";
  // One msf_holdout run per dataset and frames, all of its methods at once.
  std::map<std::pair<std::string, std::string>, std::vector<const DocumentedRow*>> runs;
  for (const auto& row : rows)
    runs[{row.dataset, row.frames}].push_back(&row);
  msf::test::TempDir dir;
  for (const auto& [run, expected] : runs) {
    std::string methods;
    for (const DocumentedRow* row : expected)
      methods += (methods.empty() ? "" : ",") + row->method;
    const auto r = msf::test::runTool("msf_holdout", msf::test::kittiDir() + "/" + run.first + " -frames " +
                                                         run.second + " -methods " + methods + " -csv " +
                                                         dir.file("rows.csv") + " -overwrite");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto measured = holdoutRows(dir.file("rows.csv"));
    for (const DocumentedRow* row : expected) {
      ASSERT_TRUE(measured.count(row->method)) << row->method << " in\n" << r.out;
      const auto& m = measured.at(row->method);
      const std::string what = run.first + " " + run.second + " " + row->method + ":\n" + r.out;
      // To the digits docs/paper.md shows, one unit of slack (OpenCV's SGBM strips follow the core count).
      EXPECT_NEAR(m[0], row->coverage, 2e-4) << what;
      EXPECT_NEAR(100 * m[1], row->d1_pct, 0.02) << what;
      EXPECT_NEAR(m[2], row->mae_m, 2e-3) << what;
    }
  }
}

} // namespace
