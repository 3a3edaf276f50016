// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Guided semi-global matching: sparse disparity hints (projected LiDAR returns) in the
// native matcher's costs, the hints made from a sparse depth, and SgbmStereo's plumbing.
#include <msf/common/exceptions.h>
#include <msf/stereo/guidance_hints.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_stereo.h>

#include "stereo_scenes.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <string>
#include <tuple>

namespace {

const cv::Size kSize(320, 160);
constexpr float kBackgroundPx = 12.f, kSquarePx = 30.f;

#define MSF_REQUIRE_AVX2()                                                                    \
  do {                                                                                        \
    if (!msf::SemiGlobalMatcher::usesAvx2())                                                  \
      GTEST_SKIP() << "this CPU has no AVX2: the native matcher is not run";                  \
  } while (0)

msf::SemiGlobalMatcher::Params guidedParams() {
  msf::SemiGlobalMatcher::Params params;
  params.num_disparities = 48;
  params.p1 = 8 * 25;
  params.p2 = 32 * 25;
  params.guidance_gain = 200;
  params.guidance_max_penalty = 1000;
  return params;
}

/// The synthetic pair with a textureless band in the background (the same grey in both
/// views), where matching alone is ambiguous.
struct FlatBandPair {
  msf::test::SyntheticPair pair;
  cv::Rect band; // left-image pixels without texture, away from its edges by a block
};

FlatBandPair makeFlatBandPair() {
  FlatBandPair scene{msf::test::makeSyntheticPair(kSize, kBackgroundPx, kSquarePx), {}};
  const cv::Rect flat(20, 100, 140, 40); // left of the square, background only
  scene.pair.left(flat).setTo(128);
  // The right view sees the same background shifted by its disparity.
  scene.pair.right(flat - cv::Point(static_cast<int>(kBackgroundPx), 0)).setTo(128);
  scene.band = cv::Rect(flat.x + 8, flat.y + 4, flat.width - 16, flat.height - 8);
  return scene;
}

/// Hints at the true disparity on every `step`-th row (as LiDAR rings are), 0 elsewhere.
cv::Mat ringHints(const cv::Mat& truth, int step, float offset_px = 0.f) {
  cv::Mat hints = cv::Mat::zeros(truth.size(), CV_16SC1);
  for (int v = 0; v < truth.rows; v += step)
    for (int u = 0; u < truth.cols; ++u)
      hints.at<short>(v, u) = static_cast<short>(std::lround(16.f * (truth.at<float>(v, u) + offset_px)));
  return hints;
}

/// Share of `roi`'s pixels with a disparity within 1 px of the truth.
double shareCorrect(const cv::Mat& fixed, const cv::Mat& truth, const cv::Rect& roi) {
  int good = 0;
  for (int v = roi.y; v < roi.y + roi.height; ++v)
    for (int u = roi.x; u < roi.x + roi.width; ++u)
      good += fixed.at<short>(v, u) > 0 && std::fabs(fixed.at<short>(v, u) / 16.f - truth.at<float>(v, u)) <= 1.f;
  return static_cast<double>(good) / roi.area();
}

TEST(GuidedMatching, CorrectHintsResolveATexturelessBand) {
  MSF_REQUIRE_AVX2();
  const FlatBandPair scene = makeFlatBandPair();
  msf::SemiGlobalMatcher matcher(guidedParams());
  cv::Mat plain, guided;
  matcher.compute(scene.pair.left, scene.pair.right, plain);
  matcher.compute(scene.pair.left, scene.pair.right, guided, ringHints(scene.pair.disparity, 2));
  const double before = shareCorrect(plain, scene.pair.disparity, scene.band);
  const double after = shareCorrect(guided, scene.pair.disparity, scene.band);
  EXPECT_LT(before, 0.55) << "the band should be ambiguous without hints";
  EXPECT_GT(after, before + 0.15); // measured 0.49 -> 0.68 with hints on every other row
  // The textured square keeps its own disparity: no hints there, image evidence wins.
  const cv::Rect inner = scene.pair.square - cv::Point(-6, -6) + cv::Size(-12, -12);
  EXPECT_GT(shareCorrect(guided, scene.pair.disparity, inner), 0.95);
}

TEST(GuidedMatching, WrongHintsPullTheBandButNotTheTexturedSquare) {
  MSF_REQUIRE_AVX2();
  const FlatBandPair scene = makeFlatBandPair();
  msf::SemiGlobalMatcher::Params params = guidedParams();
  params.guidance_max_penalty = 400;
  msf::SemiGlobalMatcher matcher(params);
  cv::Mat guided;
  // Hints 5 px off everywhere, the square included: the penalty, capped below a textured
  // block's evidence, cannot move the square, but decides the textureless band.
  matcher.compute(scene.pair.left, scene.pair.right, guided, ringHints(scene.pair.disparity, 2, 5.f));
  const cv::Rect inner = scene.pair.square - cv::Point(-6, -6) + cv::Size(-12, -12);
  EXPECT_GT(shareCorrect(guided, scene.pair.disparity, inner), 0.95);
  EXPECT_LT(shareCorrect(guided, scene.pair.disparity, scene.band), 0.1);
}

TEST(GuidedMatching, WithoutHintsTheOutputIsBitIdentical) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, kBackgroundPx, kSquarePx);
  msf::SemiGlobalMatcher::Params unguided_params = guidedParams();
  unguided_params.guidance_gain = unguided_params.guidance_max_penalty = 0;
  msf::SemiGlobalMatcher unguided(unguided_params), matcher(guidedParams());
  cv::Mat reference, empty_guidance, zero_hints, zero_gain;
  unguided.compute(pair.left, pair.right, reference);
  matcher.compute(pair.left, pair.right, empty_guidance, cv::Mat());
  matcher.compute(pair.left, pair.right, zero_hints, cv::Mat::zeros(kSize, CV_16SC1));
  unguided.compute(pair.left, pair.right, zero_gain, ringHints(pair.disparity, 2, 3.f));
  EXPECT_EQ(cv::countNonZero(reference != empty_guidance), 0);
  EXPECT_EQ(cv::countNonZero(reference != zero_hints), 0);
  EXPECT_EQ(cv::countNonZero(reference != zero_gain), 0);
}

TEST(GuidedMatching, BadGuidanceAndParametersAreRejected) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, kBackgroundPx, kSquarePx);
  msf::SemiGlobalMatcher matcher(guidedParams());
  cv::Mat fixed;
  const auto message = [&](const cv::Mat& guidance) -> std::string {
    try {
      matcher.compute(pair.left, pair.right, fixed, guidance);
    } catch (const msf::InvalidInputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(cv::Mat::zeros(kSize.height, kSize.width - 1, CV_16SC1)).find("guidance"), std::string::npos);
  EXPECT_NE(message(cv::Mat::zeros(kSize, CV_32FC1)).find("CV_16SC1"), std::string::npos);
  // Gains and caps beyond the 16-bit arithmetic's bounds, each named.
  for (const auto& [gain, cap, name] : {std::tuple{-1, 100, "'guidance_gain'"},
                                        std::tuple{msf::SemiGlobalMatcher::kMaxGuidanceGain + 1, 100, "'guidance_gain'"},
                                        std::tuple{10, -1, "'guidance_max_penalty'"},
                                        std::tuple{10, msf::SemiGlobalMatcher::kMaxGuidancePenalty + 1,
                                                   "'guidance_max_penalty'"}}) {
    msf::SemiGlobalMatcher::Params params = guidedParams();
    params.guidance_gain = gain;
    params.guidance_max_penalty = cap;
    try {
      matcher.setParams(params);
      ADD_FAILURE() << "gain " << gain << ", cap " << cap << " accepted";
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

TEST(GuidanceHints, ReturnsBecomeDisparityAndAgreeingNeighboursAreBridged) {
  const double fB = 400.0; // 10 m: 40 px
  cv::Mat sparse = cv::Mat::zeros(20, 3, CV_32FC1);
  sparse.at<float>(2, 0) = 10.f;  // 40 px ...
  sparse.at<float>(10, 0) = 8.f;  // ... 50 px, 8 rows below: bridged
  sparse.at<float>(2, 1) = 10.f;  // 40 px ...
  sparse.at<float>(10, 1) = 4.f;  // ... 100 px: a depth edge, not bridged
  sparse.at<float>(2, 2) = 10.f;
  sparse.at<float>(19, 2) = 10.f; // 17 rows apart: beyond the bridge
  const cv::Mat hints = msf::guidanceHints(sparse, fB, 16, 0.25f);
  ASSERT_EQ(hints.type(), CV_16SC1);
  EXPECT_EQ(hints.at<short>(2, 0), 40 * 16);
  EXPECT_EQ(hints.at<short>(10, 0), 50 * 16);
  for (int v = 3; v < 10; ++v) // linear between the two
    EXPECT_EQ(hints.at<short>(v, 0), std::lround(16.0 * (40.0 + 10.0 * (v - 2) / 8.0))) << v;
  EXPECT_EQ(hints.at<short>(0, 0), 0);
  EXPECT_EQ(hints.at<short>(11, 0), 0);
  for (int v = 3; v < 10; ++v)
    EXPECT_EQ(hints.at<short>(v, 1), 0) << v;
  EXPECT_EQ(hints.at<short>(10, 1), 100 * 16);
  for (int v = 3; v < 19; ++v)
    EXPECT_EQ(hints.at<short>(v, 2), 0) << v;
  // Without a bridge, the returns only.
  EXPECT_EQ(cv::countNonZero(msf::guidanceHints(sparse, fB) != 0), 6);
  EXPECT_THROW(msf::guidanceHints(cv::Mat::zeros(4, 4, CV_64FC1), fB), msf::InvalidInputError);
  EXPECT_THROW(msf::guidanceHints(sparse, 0.0), msf::InvalidInputError);
}

TEST(GuidanceHints, RightViewHintsMoveByTheirDisparityAndAreMirrored) {
  cv::Mat hints = cv::Mat::zeros(1, 10, CV_16SC1);
  hints.at<short>(0, 5) = 3 * 16; // lands on right column 2 ...
  hints.at<short>(0, 6) = 4 * 16; // ... as does this nearer one, which wins
  hints.at<short>(0, 8) = 2 * 16 + 4; // 2.25 px: column 6
  hints.at<short>(0, 1) = 5 * 16; // outside the right image
  const cv::Mat right = msf::rightViewHintsMirrored(hints);
  ASSERT_EQ(right.type(), CV_16SC1);
  EXPECT_EQ(right.at<short>(0, 9 - 2), 4 * 16);
  EXPECT_EQ(right.at<short>(0, 9 - 6), 2 * 16 + 4);
  EXPECT_EQ(cv::countNonZero(right), 2);
  EXPECT_THROW(msf::rightViewHintsMirrored(cv::Mat::zeros(1, 10, CV_32FC1)), msf::InvalidInputError);
}

/// The sparse depth of a LiDAR seeing the truth on every `step`-th row.
cv::Mat ringDepth(const cv::Mat& truth, const msf::Calibration& calibration, int step) {
  cv::Mat depth = cv::Mat::zeros(truth.size(), CV_32FC1);
  for (int v = 0; v < truth.rows; v += step)
    for (int u = 0; u < truth.cols; ++u)
      depth.at<float>(v, u) = static_cast<float>(calibration.focalBaseline()) / truth.at<float>(v, u);
  return depth;
}

msf::SgbmConfig guidedConfig() {
  msf::SgbmConfig config;
  // Three paths, guided or not, so that only the hints fill the band: five carry the texture
  // beside it in along their diagonals (unguided, 0.78 of the band right).
  config.mode = config.unguided_mode = "sgbm_3way";
  config.num_disparities_px = 48;
  config.guidance = "lidar";
  config.guidance_gain = 200;
  config.guidance_max_penalty = 1000;
  config.guidance_bridge_rows = 8;
  return config;
}

/// Share of the band's pixels within 1 px of the truth, from SgbmStereo with `config`
/// guided by `sparse` (rings of the true depth, or empty).
double sgbmStereoBandShare(const FlatBandPair& scene, const msf::SgbmConfig& config, const cv::Mat& sparse) {
  msf::SgbmStereo stereo(config);
  stereo.setCalibration(msf::test::syntheticCalibration(kSize));
  stereo.setInputImages(scene.pair.left, scene.pair.right);
  stereo.setGuidance(sparse);
  stereo.computeDisparity();
  const cv::Mat& d = stereo.getDisparity();
  int good = 0;
  for (int v = scene.band.y; v < scene.band.br().y; ++v)
    for (int u = scene.band.x; u < scene.band.br().x; ++u)
      good += std::fabs(d.at<float>(v, u) - kBackgroundPx) <= 1.f;
  return static_cast<double>(good) / scene.band.area();
}

TEST(GuidedMatching, SgbmStereoGuidedByASparseDepthBridgesTheRings) {
  MSF_REQUIRE_AVX2();
  const FlatBandPair scene = makeFlatBandPair();
  const cv::Mat sparse = ringDepth(scene.pair.disparity, msf::test::syntheticCalibration(kSize), 5); // 5 rows apart
  const auto correct = [&](const msf::SgbmConfig& config) { return sgbmStereoBandShare(scene, config, sparse); };
  msf::SgbmConfig unguided = guidedConfig(), returns_only = guidedConfig();
  unguided.guidance = "none"; // the sparse depth is then ignored
  returns_only.guidance_bridge_rows = 0;
  const double none = correct(unguided), rings = correct(returns_only), bridged = correct(guidedConfig());
  // Measured 0.42, 0.42 and 0.84: the paths alone carry hints 5 rows apart little way.
  EXPECT_LT(none, 0.5);
  EXPECT_GT(bridged, 0.75);
  EXPECT_GT(bridged, rings + 0.3);
}

TEST(GuidedMatching, TheRightViewAndThePaddedBorderAreGuidedToo) {
  MSF_REQUIRE_AVX2();
  const FlatBandPair scene = makeFlatBandPair();
  const cv::Mat sparse = ringDepth(scene.pair.disparity, msf::test::syntheticCalibration(kSize), 5);
  const auto correct = [&](bool left_right_check, bool left_border, const cv::Mat& guidance) {
    msf::SgbmConfig config = guidedConfig();
    config.left_right_check = left_right_check;
    config.match_left_border = left_border;
    return sgbmStereoBandShare(scene, config, guidance);
  };
  // The explicit left-right check matches the mirrored pair: its hints are the left ones
  // moved to the right view (measured 0.49 -> 0.81); the padded pair's are padded (0.97 -> 1).
  EXPECT_GT(correct(true, false, sparse), correct(true, false, cv::Mat()) + 0.2);
  const double border = correct(false, true, sparse);
  EXPECT_GT(border, 0.95);
  EXPECT_GE(border, correct(false, true, cv::Mat()));
}

TEST(GuidedMatching, SgbmConfigRejectsBadGuidanceKeysAndOpenCvIgnoresGuidance) {
  msf::SgbmConfig config = guidedConfig();
  const auto rejected_key = [](const msf::SgbmConfig& c) -> std::string {
    try {
      c.validate();
    } catch (const msf::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  config.guidance = "stereo";
  EXPECT_EQ(rejected_key(config), "stereo.guidance must be lidar | none, not 'stereo'");
  config = guidedConfig();
  config.guidance_bridge_rows = -1;
  EXPECT_EQ(rejected_key(config), "stereo.guidance_bridge_rows must be >= 0, not -1");
  config = guidedConfig();
  config.guidance_gain = msf::SemiGlobalMatcher::kMaxGuidanceGain + 1;
  EXPECT_EQ(rejected_key(config).rfind("stereo.guidance_gain must be in 0..", 0), 0u) << rejected_key(config);

  // OpenCV's StereoSGBM takes no guidance: with it, the sparse depth changes nothing.
  const FlatBandPair scene = makeFlatBandPair();
  const msf::Calibration calibration = msf::test::syntheticCalibration(kSize);
  const auto disparity = [&](const cv::Mat& sparse) {
    msf::SgbmConfig opencv = guidedConfig();
    opencv.engine = "opencv";
    msf::SgbmStereo stereo(opencv);
    stereo.setCalibration(calibration);
    stereo.setInputImages(scene.pair.left, scene.pair.right);
    stereo.setGuidance(sparse);
    stereo.computeDisparity();
    EXPECT_EQ(stereo.getEngineUsed(), "opencv");
    return stereo.getDisparity().clone();
  };
  EXPECT_EQ(cv::countNonZero(disparity(cv::Mat()) != disparity(ringDepth(scene.pair.disparity, calibration, 5))), 0);

  // A sparse depth of the wrong size or type is named.
  MSF_REQUIRE_AVX2();
  msf::SgbmStereo stereo(guidedConfig());
  stereo.setCalibration(calibration);
  stereo.setInputImages(scene.pair.left, scene.pair.right);
  for (const cv::Mat& bad : {cv::Mat(cv::Mat::zeros(10, 10, CV_32FC1)), cv::Mat(cv::Mat::zeros(kSize, CV_16UC1))}) {
    stereo.setGuidance(bad);
    try {
      stereo.computeDisparity();
      ADD_FAILURE() << "a bad sparse depth was accepted";
    } catch (const msf::InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find("guidance"), std::string::npos) << e.what();
    }
  }
}

} // namespace
