// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The memory budget of msf_reconstruct: with the poses known before the run, its peak is predicted
// (Reconstructor::predictMemory) within a stated factor above the measured one; a run predicted
// over the budget streams its map on its own when its evaluations allow, and is refused before
// it starts when it needs the whole map or an explicit budget is too small even streamed.
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <string>

namespace {

/// The prediction is at least the measured peak and at most this many times it.
constexpr double kMaxOverPrediction = 1.5;

/// How far from the prediction a budget is set to land surely on one side of it: the prediction
/// varies by a few MiB from run to run with the process's own memory when it predicts.
constexpr long kMarginMb = 10;

/// The figure N of "predicted to need up to N MiB" in a refusal, or -1.
long predictedIn(const std::string& err) {
  std::smatch m;
  return std::regex_search(err, m, std::regex("predicted to need up to ([0-9]+) MiB")) ? std::stol(m[1]) : -1;
}

/// The predicted and measured peaks of a run's summary.json, printed, and the prediction within
/// [1, kMaxOverPrediction] times the measure.
void expectPredictionHolds(const std::string& out, const char* what) {
  const std::string json = readFile(out + "/summary.json");
  const double said = jsonNumber(json, "predicted_memory_mb"), peak = jsonNumber(json, "peak_memory_mb");
  EXPECT_GE(said, peak) << "a budget the prediction lets through holds the run: " << json;
  EXPECT_LE(said, kMaxOverPrediction * peak) << json;
  std::printf("%s: predicted %.0f MiB, measured peak %.0f MiB (%.2fx)\n", what, said, peak, said / peak);
}

TEST_F(PipelineTest, ThePredictedPeakHoldsTheMeasuredOneAndABudgetBelowItStreamsOrRefuses) {
#ifdef __SANITIZE_ADDRESS__
  GTEST_SKIP() << "the prediction models a build without AddressSanitizer, whose shadow memory it does not count";
#endif
  msf::test::TempDir dir;
  const std::string frames = " -frames 0:0 -panels 0";
  // A budget below even the streamed prediction: refused before any frame is read, naming both
  // figures (the bound's: the calibration frame does not fit either); no OUT, no staging folder
  // beside it.
  const std::string refused = dir.file("refused");
  const auto no = msf::test::runTool("msf_reconstruct", dataset() + " -o " + refused + frames + " -max_memory 10");
  EXPECT_EQ(no.exit_code, 1) << no.out << no.err;
  EXPECT_NE(no.err.find("msf_reconstruct: error: the run is predicted to need up to "), std::string::npos) << no.err;
  EXPECT_NE(no.err.find(" MiB streamed with an active radius of "), std::string::npos) << no.err;
  EXPECT_NE(no.err.find("over the memory budget of 10 MiB (tsdf_volume.max_memory_mb, -max_memory)"), std::string::npos)
      << no.err;
  EXPECT_EQ(no.out.find("Reconstructing"), std::string::npos) << "refused before the run: " << no.out;
  EXPECT_FALSE(std::filesystem::exists(refused));
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u) << "a staging folder is left";
  EXPECT_GT(predictedIn(no.err), 10) << no.err;
  // A calibration frame's blocks do not fit 10 MiB, so these figures are the views' bound, far
  // above the run's prediction: not a budget to test streaming against.
  EXPECT_NE(no.err.find("(the bound: every block the views meet)"), std::string::npos) << no.err;

  // The in-memory prediction, as a run with a budget far above it prints it (its calibration
  // frames fit).
  const std::string wide = dir.file("wide");
  const auto ample = msf::test::runTool("msf_reconstruct", dataset() + " -o " + wide + frames + " -max_memory 100000");
  ASSERT_EQ(ample.exit_code, 0) << ample.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ample.out, m, std::regex("Memory: predicted peak ([0-9]+) MiB"))) << ample.out;
  const long in_memory = std::stol(m[1]);
  ASSERT_GT(in_memory, 100) << ample.out;

  // Just above the prediction: the run goes in memory, and its measured peak is below the
  // prediction.
  const std::string above = dir.file("above");
  const auto yes = msf::test::runTool("msf_reconstruct", dataset() + " -o " + above + frames + " -max_memory " +
                                                             std::to_string(in_memory + kMarginMb));
  ASSERT_EQ(yes.exit_code, 0) << yes.err;
  EXPECT_NE(yes.out.find("Memory: predicted peak"), std::string::npos) << yes.out;
  EXPECT_EQ(yes.out.find("streaming the map"), std::string::npos) << yes.out;
  expectPredictionHolds(above, "synthetic street, 1 frame, in memory");

  // The streamed prediction, as a run with a budget just below the in-memory one prints it,
  // streaming or refused.
  const auto probe = msf::test::runTool("msf_reconstruct", dataset() + " -o " + dir.file("probe") + frames +
                                                               " -max_memory " + std::to_string(in_memory - kMarginMb));
  ASSERT_TRUE(std::regex_search(probe.out, m, std::regex("predicted peak streamed ([0-9]+) MiB")) ||
              std::regex_search(probe.err, m, std::regex("and ([0-9]+) MiB streamed")))
      << probe.out << probe.err;
  const long streamed = std::stol(m[1]);
  ASSERT_GT(in_memory, streamed + 4) << "streaming predicts no less than keeping the map in memory";

  // Between the two: the run streams on its own (its mesh written tile by tile), says so, and
  // stays within the budget.
  const long budget = (in_memory + streamed) / 2;
  const std::string between = dir.file("between");
  const auto streams = msf::test::runTool("msf_reconstruct", dataset() + " -o " + between + frames + " -max_memory " +
                                                                 std::to_string(budget));
  ASSERT_EQ(streams.exit_code, 0) << streams.err;
  EXPECT_NE(streams.out.find("over the budget of " + std::to_string(budget) +
                             " MiB: streaming the map with an active radius of "),
            std::string::npos)
      << streams.out;
  EXPECT_NE(streams.out.find("(tiles in " + between + "/tiles)"), std::string::npos) << streams.out;
  EXPECT_TRUE(std::filesystem::is_directory(between + "/tiles"));
  EXPECT_LE(jsonNumber(readFile(between + "/summary.json"), "peak_memory_mb"), static_cast<double>(budget));
  expectPredictionHolds(between, "synthetic street, 1 frame, streamed on its own");

  // The same budget for a run that needs the whole map in memory: refused.
  const auto whole = msf::test::runTool("msf_reconstruct", dataset() + " -o " + refused + frames +
                                                               " -compare_sources -max_memory " + std::to_string(budget));
  EXPECT_EQ(whole.exit_code, 1) << whole.err;
  EXPECT_NE(whole.err.find("the run needs the whole map in memory (-compare_sources)"), std::string::npos)
      << whole.err;
  EXPECT_FALSE(std::filesystem::exists(refused));
}

TEST_F(PipelineTest, EstimatedPosesAreNotPredictedAndTheVolumeStillStopsTheRun) {
  // Nothing to predict from: the run starts, says so, and the volume's own check stops it at
  // the first frame whose blocks would not fit.
  msf::test::TempDir dir;
  const std::string out = dir.file("out");
  const auto r = msf::test::runTool("msf_reconstruct",
                                    dataset() + " -o " + out + " -frames 0:0 -panels 0 -poses estimate -max_memory 1");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("the poses are estimated as the run goes, so its peak is not predicted"), std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("the TSDF volume needs"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("over its memory budget of 1 MiB"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(PipelineTest, AStreamedMapIsPredictedWithinItsWindow) {
  // The same poses, streamed with a small window, predict fewer blocks in memory than in all.
  const msf::Sequence sequence(dataset());
  const auto frames = sequence.indices(msf::FrameRange::parse("0:"));
  msf::PoseList poses;
  for (std::size_t i : frames)
    poses.push_back(sequence.poses()[i]);
  msf::PipelineConfig config;
  auto predict = [&](int maps) {
    return msf::Reconstructor(sequence.calibration(), config).predictMemory(sequence, frames, poses, maps);
  };
  const msf::MemoryPrediction whole = predict(1);
  EXPECT_GT(whole.blocks_per_band_block, 0.0) << "measured on the street's frames";
  EXPECT_GT(whole.band_blocks, 0u);
  EXPECT_LT(whole.blocks, whole.footprint_blocks) << "the scans' bands are far tighter than the views' bound";
  EXPECT_EQ(whole.blocks_in_memory, whole.blocks);
  EXPECT_GT(predict(3).volume_mb, 2 * whole.volume_mb) << "two more maps";
  config.streaming.active_radius_m = 1000.0;
  EXPECT_EQ(predict(1).blocks_in_memory, whole.blocks) << "a window wider than the drive holds all of it";
  config.streaming.active_radius_m = 5.0;
  const msf::MemoryPrediction narrow = predict(1);
  EXPECT_EQ(narrow.blocks, whole.blocks);
  EXPECT_LT(narrow.blocks_in_memory, whole.blocks_in_memory);
  EXPECT_LT(narrow.volume_mb, whole.volume_mb);
  EXPECT_NE(narrow.describe().find("in memory at once"), std::string::npos) << narrow.describe();
}

TEST_F(PipelineTest, TheGroundTruthKeptIsPredictedByItsPixels) {
  // What a run keeps to score the mesh at the end is counted by the pixels kept a frame: a
  // synthetic drive's every pixel, or under -holdout its held-out returns, which the scans bound.
  const msf::Sequence sequence(dataset());
  const auto frames = sequence.indices(msf::FrameRange::parse("0:"));
  msf::PoseList poses;
  std::size_t most_returns = 0;
  for (std::size_t i : frames) {
    poses.push_back(sequence.poses()[i]);
    most_returns = std::max(most_returns, sequence.loadScan(i)->size());
  }
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  const msf::MemoryEvidence evidence = engine.measureMemory(sequence, frames, poses);
  EXPECT_EQ(evidence.most_scan_returns, most_returns);
  const msf::MemoryPrediction none = engine.predictMemory(evidence);
  const msf::MemoryPrediction every = engine.predictMemory(evidence, 1, 1000.0 * 1000.0);
  const double mib = 1024.0 * 1024.0, kept_mb = 8.0 * 1000.0 * 1000.0 * static_cast<double>(frames.size()) / mib;
  EXPECT_NEAR(every.frames_mb - none.frames_mb, kept_mb, 1e-6) << "8 bytes a pixel a frame";
  EXPECT_NEAR(every.total_mb - none.total_mb, kept_mb, 1e-6);
  EXPECT_EQ(every.volume_mb, none.volume_mb);
}

TEST(MemoryPrediction, HeldOutRingsAddTheirReturnsNotAnImageAFrame) {
  // KITTI under -holdout keeps a few thousand held-out pixels a frame, not an image: the frames'
  // term of its prediction is the run's without -holdout and a MiB or two (the returns of a ring in
  // four, 8 bytes each, five frames), and its peak is below the prediction.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string drive = msf::test::kittiDir() + "/odometry/sequences/04 -frames 0:4 -panels 0";
  long frames_mb[2] = {0, 0};
  for (const bool holdout : {false, true}) {
    const std::string out = dir.file(holdout ? "holdout" : "plain");
    const auto r = msf::test::runTool("msf_reconstruct", drive + (holdout ? " -holdout" : "") + " -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, std::regex("frames and stage buffers ([0-9]+) MiB"))) << r.out;
    frames_mb[holdout] = std::stol(m[1]);
    if (holdout)
      expectPredictionHolds(out, "odometry 04, 5 frames, under -holdout");
  }
  EXPECT_GE(frames_mb[1] - frames_mb[0], 0);
  EXPECT_LE(frames_mb[1] - frames_mb[0], 2) << "a canvas a frame, as the model had it, would be 40 MiB";
}

} // namespace
