// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/run_report.h>

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

using msf::RunReport;

namespace {
RunReport reportOf(std::size_t frames, double wall_s, double first_frame_s) {
  RunReport report;
  report.frames.resize(frames);
  report.wall_s = wall_s;
  report.first_frame_s = first_frame_s;
  return report;
}

/// The report.md `report` writes.
std::string markdownOf(const RunReport& report, const std::string& name) {
  const std::string path = ::testing::TempDir() + name;
  report.writeMarkdown(path);
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
} // namespace

TEST(RunReport, RateAfterTheFirstFrameLeavesOutTheFillingOfThePipeline) {
  // 10 frames in 1.2 s, the first done at 0.3 s: 9 frames in the last 0.9 s.
  const RunReport report = reportOf(10, 1.2, 0.3);
  EXPECT_DOUBLE_EQ(report.framesPerSecond(), 10 / 1.2);
  EXPECT_DOUBLE_EQ(report.framesPerSecondAfterFirst(), 10.0);
}

TEST(RunReport, RateAfterTheFirstFrameNeedsTwoFrames) {
  EXPECT_EQ(reportOf(1, 0.5, 0.5).framesPerSecondAfterFirst(), 0.0);
  EXPECT_EQ(reportOf(0, 0.0, 0.0).framesPerSecondAfterFirst(), 0.0);
  EXPECT_EQ(reportOf(3, 0.5, 0.5).framesPerSecondAfterFirst(), 0.0); // no time after the first: no rate
}

TEST(RunReport, IntegersEndingInZeroKeepTheirDigits) {
  // num() stripped the trailing zeros of every number, those of an integer too: 720 MiB -> "72".
  RunReport report = reportOf(2, 1.0, 0.5);
  report.peak_memory_mb = 7200;  // above this test process's own peak, which the report takes if larger
  report.observed_voxels = 100;
  report.mesh_ms = 10;
  const std::string text = markdownOf(report, "run_report_integers.md");
  EXPECT_NE(text.find("peak memory 7200 MiB"), std::string::npos) << text;
  EXPECT_NE(text.find("mesh extraction 10 ms"), std::string::npos) << text;
  EXPECT_NE(text.find("2 frames per second"), std::string::npos) << text;
}

TEST(RunReport, TheSkysCoverHasADepthOnlyWhereTheMeshCoversIt) {
  RunReport report = reportOf(2, 1.0, 0.5);
  msf::SkyCoverage& empty = report.open_sky["mesh"];
  empty.frames = 2;
  empty.sky_pixels = 93148;
  msf::SkyCoverage& covered = report.open_sky["mesh_lidar"];
  covered.frames = 2;
  covered.sky_pixels = 93148;
  covered.covered_pixels = 120;
  covered.share = 120.0 / 93148;
  covered.covered_depth_median_m = 32.4;
  const std::string text = markdownOf(report, "run_report_sky.md");
  EXPECT_NE(text.find("| mesh | 2 | 93148 | 0 % | 0 % | 0 % (frame 0) | none |"), std::string::npos) << text;
  EXPECT_NE(text.find("(frame 0) | 32.4 m |"), std::string::npos) << text;
}
