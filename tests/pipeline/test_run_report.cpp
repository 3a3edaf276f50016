#include <msf/pipeline/run_report.h>

#include <gtest/gtest.h>

using msf::RunReport;

namespace {
RunReport reportOf(std::size_t frames, double wall_s, double first_frame_s) {
  RunReport report;
  report.frames.resize(frames);
  report.wall_s = wall_s;
  report.first_frame_s = first_frame_s;
  return report;
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
