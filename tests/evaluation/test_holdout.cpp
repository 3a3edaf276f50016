// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Protocol 2 (ring hold-out) on the real KITTI sample: the split, the runner with oracle
// methods, the published IP-Basic figures, the issue's targets, and the msf_holdout tool.
#include <msf/common/exceptions.h>
#include <msf/evaluation/holdout.h>
#include <msf/io/sequence.h>
#include <msf/range_image/lidar_completion.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <fstream>
#include <memory>
#include <sstream>

namespace {

std::string odometry() { return msf::test::kittiDir() + "/odometry/sequences/04"; }

/// A LiDAR method of LidarCompletion, made at the first frame.
msf::HoldoutMethod lidar(msf::CompletionMethod method, msf::ProjectionConfig projection = {}) {
  auto completion = std::make_shared<std::unique_ptr<msf::LidarCompletion>>();
  return [=](const msf::HoldoutInput& in) {
    if (!*completion)
      *completion = std::make_unique<msf::LidarCompletion>(*in.calibration, method, projection);
    cv::Mat depth;
    (*completion)->computeDepth(*in.scan, depth);
    return depth;
  };
}

TEST(Holdout, SplitsAFrameIntoInputRingsAndGroundTruth) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(odometry());
  const msf::Frame frame = sequence.load(0, false);
  const msf::HoldoutFrame split = msf::makeHoldoutFrame(frame, sequence.calibration(), msf::HoldoutConfig());
  EXPECT_EQ(split.ring_count, 65);
  EXPECT_EQ(split.input.scan->size() + split.heldout_points, frame.scan->size());
  EXPECT_EQ(split.input.calibration, &sequence.calibration());
  EXPECT_EQ(split.input.left.size(), cv::Size(1226, 370));
  ASSERT_EQ(split.gt_depth.size(), cv::Size(1226, 370));
  const int gt = cv::countNonZero(split.gt_depth);
  EXPECT_GT(gt, 3000); // a quarter of the rings, about 5000 pixels
  EXPECT_LT(gt, 8000);
  msf::HoldoutConfig camera1;
  camera1.projection.camera = 1;
  EXPECT_THROW(msf::makeHoldoutFrame(frame, sequence.calibration(), camera1), msf::ConfigError);
}

TEST(Holdout, OracleAndEmptyMethodsGiveTheExtremes) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(odometry());
  msf::HoldoutEvaluation evaluation;
  // The oracle re-reads the frame and projects the held-out rings: exactly the truth.
  evaluation.addMethod("oracle", [&](const msf::HoldoutInput& in) {
    return msf::makeHoldoutFrame(sequence.load(in.frame, false), *in.calibration, msf::HoldoutConfig()).gt_depth;
  });
  evaluation.addMethod("empty", [](const msf::HoldoutInput& in) {
    return cv::Mat(in.left.size(), CV_32FC1, cv::Scalar(0));
  });
  std::size_t progress = 0;
  evaluation.setProgress([&](std::size_t done, std::size_t all) {
    EXPECT_EQ(all, 2u);
    progress = done;
  });
  const auto results = evaluation.run(sequence, {0, 1});
  EXPECT_EQ(progress, 2u);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].method, "oracle");
  EXPECT_EQ(results[0].frames, 2u);
  EXPECT_EQ(results[0].metrics.coverage, 1.0);
  EXPECT_EQ(results[0].metrics.d1_all, 0.0);
  EXPECT_EQ(results[0].metrics.mae_m, 0.0);
  EXPECT_EQ(results[1].metrics.coverage, 0.0);
  EXPECT_EQ(results[1].metrics.d1_all, 1.0);
  EXPECT_EQ(results[0].metrics.gt_pixels, results[1].metrics.gt_pixels);
  EXPECT_GE(results[0].median_ms, 0.0);

  const std::string table = msf::formatHoldoutTable(results);
  EXPECT_NE(table.find("coverage"), std::string::npos);
  EXPECT_NE(table.find("oracle"), std::string::npos);
  EXPECT_NE(table.find("100.00%"), std::string::npos); // the empty method's D1
  msf::test::TempDir tmp;
  msf::writeHoldoutCsv(tmp.file("rows.csv"), results);
  std::ifstream csv(tmp.file("rows.csv"));
  std::string header, first, second, extra;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_EQ(header.rfind("method,frames,gt_pixels", 0), 0u) << header;
  EXPECT_EQ(first.rfind("oracle,2,", 0), 0u) << first;
  EXPECT_EQ(second.rfind("empty,2,", 0), 0u) << second;
  EXPECT_FALSE(std::getline(csv, extra));
  EXPECT_THROW(msf::writeHoldoutCsv("/nonexistent/dir/rows.csv", results), msf::IOError);
}

TEST(Holdout, MethodsAreNamedOnceAndTheirOutputIsChecked) {
  MSF_REQUIRE_KITTI();
  msf::HoldoutEvaluation evaluation;
  evaluation.addMethod("small", [](const msf::HoldoutInput&) { return cv::Mat(10, 10, CV_32FC1, cv::Scalar(1)); });
  EXPECT_THROW(evaluation.addMethod("small", [](const msf::HoldoutInput&) { return cv::Mat(); }),
               msf::InvalidInputError);
  EXPECT_THROW(evaluation.addMethod("", [](const msf::HoldoutInput&) { return cv::Mat(); }), msf::InvalidInputError);
  try {
    evaluation.run(msf::Sequence(odometry()), {0});
    FAIL();
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("'small'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(msf::HoldoutEvaluation().run(msf::Sequence(odometry()), {0}), msf::InvalidInputError);
}

TEST(Holdout, PublishedIpBasicFiguresAndTheIssueTargets) {
  // The brief's protocol-2 baseline (docs/results.md): IP-Basic multiscale on the image's own projection has
  // coverage 0.993, D1 (missing = bad) 6.1 %, depth MAE 1.87 m on odometry 04 frames 0-9.
  // The compound interpolation (defaults) must reach coverage >= 0.99, D1 <= 5 %, MAE <= 1.5 m.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(odometry());
  msf::ProjectionConfig no_margin;
  no_margin.margin_px = 0;
  msf::HoldoutEvaluation evaluation;
  evaluation.addMethod("ipbasic_multiscale", lidar(msf::CompletionMethod::IpBasicMultiscale, no_margin));
  evaluation.addMethod("interpolated", lidar(msf::CompletionMethod::Compound));
  const auto results = evaluation.run(sequence, sequence.indices(msf::FrameRange::parse("0:9")));
  const msf::DepthMetrics& ip = results[0].metrics;
  EXPECT_NEAR(ip.coverage, 0.993, 0.001);
  EXPECT_NEAR(ip.d1_all, 0.061, 0.001);
  EXPECT_NEAR(ip.mae_m, 1.87, 0.01);
  const msf::DepthMetrics& ours = results[1].metrics;
  EXPECT_GE(ours.coverage, 0.99);
  EXPECT_LE(ours.d1_all, 0.05);
  EXPECT_LE(ours.mae_m, 1.5);
  EXPECT_LT(ours.d1_all, ip.d1_all);
}

TEST(Holdout, FusionBoundsOfTwoMethodsAreNoWorseThanEither) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(odometry());
  msf::HoldoutEvaluation evaluation;
  evaluation.addMethod("interpolated", lidar(msf::CompletionMethod::Compound));
  evaluation.addMethod("ipbasic", lidar(msf::CompletionMethod::IpBasicFast));
  EXPECT_THROW(evaluation.addFusionBounds("interpolated", "interpolated"), msf::InvalidInputError);
  try {
    evaluation.addFusionBounds("interpolated", "sgbm");
    FAIL();
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("'sgbm' is not a method"), std::string::npos) << e.what();
  }
  evaluation.addFusionBounds("interpolated", "ipbasic");
  evaluation.addMethod("cubic", lidar(msf::CompletionMethod::Cubic)); // a third method, measured against the two
  const auto results = evaluation.run(sequence, {0, 1});
  ASSERT_EQ(results.size(), 5u);
  EXPECT_EQ(results[3].method, "bound_select");
  EXPECT_EQ(results[4].method, "bound_blend");
  const msf::DepthMetrics &a = results[0].metrics, &b = results[1].metrics;
  const msf::DepthMetrics &select = results[3].metrics, &blend = results[4].metrics;
  // Coverage of one input or the other; errors no larger than the better input's, and blending's no
  // larger than choosing's. Both inputs err, so the bounds are not the truth itself.
  EXPECT_GE(select.coverage, std::max(a.coverage, b.coverage));
  EXPECT_LE(select.coverage, a.coverage + b.coverage);
  EXPECT_EQ(blend.coverage, select.coverage);
  EXPECT_LT(select.mae_m, std::min(a.mae_m, b.mae_m));
  EXPECT_LE(blend.mae_m, select.mae_m);
  EXPECT_GT(blend.mae_m, 0.0);
  EXPECT_LE(blend.d1_all, std::min(a.d1_all, b.d1_all));
  EXPECT_LE(blend.d1_all, select.d1_all);

  // The third method's losses: its bad pixels where an input is right, which with the
  // bound's bad pixels cover all of its own.
  EXPECT_FALSE(results[0].lost_to_bound || results[1].lost_to_bound || results[3].lost_to_bound);
  ASSERT_TRUE(results[2].lost_to_bound);
  const msf::FusionLoss& loss = *results[2].lost_to_bound;
  const msf::DepthMetrics& third = results[2].metrics;
  ASSERT_EQ(loss.ground_truth, third.gt_pixels);
  const double lost = static_cast<double>(loss.lost()) / static_cast<double>(loss.ground_truth);
  EXPECT_GT(lost, 0.0);
  EXPECT_LE(lost, third.d1_all);
  EXPECT_LE(third.d1_all, lost + select.d1_all + 1e-12);
}

TEST(HoldoutTool, PrintsOneRowPerMethodAndWritesCsv) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir tmp;
  const std::string csv = tmp.file("table.csv");
  auto r = msf::test::runTool("msf_holdout", "'" + odometry() + "' -frames 0:1 -methods interpolated,ipbasic -csv '" +
                                                 csv + "' -bounds ipbasic,interpolated");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("method"), std::string::npos);
  EXPECT_NE(r.out.find("interpolated"), std::string::npos);
  EXPECT_NE(r.out.find("ipbasic"), std::string::npos);
  EXPECT_NE(r.out.find("bound_select"), std::string::npos);
  EXPECT_NE(r.out.find("bound_blend"), std::string::npos);
  std::ifstream in(csv);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 5); // header, 2 methods, 2 bounds
}

TEST(HoldoutTool, ErrorsNameTheProblemAndWriteNoCsv) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir tmp;
  const std::string csv = " -csv '" + tmp.file("t.csv") + "'";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"'" + odometry() + "' -methods interpolated,sgbm_typo" + csv, "sgbm_typo"},
      {"'" + odometry() + "' -frames 7:3" + csv, "7:3"},
      {"'" + odometry() + "' -frames 50:60" + csv, "selects no frame"},
      {"/nonexistent/sequence" + csv, "/nonexistent/sequence"},
      {"'" + odometry() + "' -csv '" + tmp.file("t.txt") + "'", ".csv"},
      {"'" + odometry() + "' -methods interpolated,ipbasic -bounds interpolated" + csv, "-bounds needs two methods"},
      {"'" + odometry() + "' -methods interpolated,ipbasic -bounds interpolated,sgbm" + csv, "'sgbm' is not a method"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = msf::test::runTool("msf_holdout", args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_NE(r.err.find("msf_holdout: error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(msf::test::countEntries(tmp.path()), 0u) << args;
  }
}

} // namespace
