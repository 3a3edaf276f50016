// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/image_io.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_stereo.h>

#include "stereo_scenes.h"
#include "test_support.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

namespace {

const cv::Size kSize(320, 160);

#define MSF_REQUIRE_AVX2()                                                                    \
  do {                                                                                        \
    if (!msf::SemiGlobalMatcher::usesAvx2())                                                  \
      GTEST_SKIP() << "this CPU has no AVX2: the native matcher is not run";                  \
  } while (0)

/// Disables the AVX2 kernel for one scope.
struct Avx2Disabled {
  Avx2Disabled() { msf::SemiGlobalMatcher::setAvx2Enabled(false); }
  ~Avx2Disabled() { msf::SemiGlobalMatcher::setAvx2Enabled(true); }
};

msf::SemiGlobalMatcher::Params smallParams() {
  msf::SemiGlobalMatcher::Params params;
  params.num_disparities = 48;
  params.p1 = 8 * 25;
  params.p2 = 32 * 25;
  return params;
}

/// Share of the pixels of `roi` whose disparity (x16) is within `tolerance_px` of `truth`.
double shareWithin(const cv::Mat& fixed, const cv::Mat& truth, const cv::Rect& roi, float tolerance_px) {
  int good = 0;
  for (int v = roi.y; v < roi.y + roi.height; ++v)
    for (int u = roi.x; u < roi.x + roi.width; ++u)
      good += fixed.at<short>(v, u) > 0 && std::fabs(fixed.at<short>(v, u) / 16.f - truth.at<float>(v, u)) <= tolerance_px;
  return static_cast<double>(good) / roi.area();
}

/// Pixels where both have a disparity, and those of them that differ by more than 1 px;
/// and the pixels where only one has a disparity.
struct Agreement {
  int both = 0, apart = 0, only_one = 0;
};

Agreement compare(const cv::Mat& a, const cv::Mat& b) {
  Agreement result;
  for (int v = 0; v < a.rows; ++v)
    for (int u = 0; u < a.cols; ++u) {
      const int da = a.at<short>(v, u), db = b.at<short>(v, u);
      if (da >= 0 && db >= 0) {
        ++result.both;
        result.apart += std::abs(da - db) > 16;
      } else if ((da >= 0) != (db >= 0)) {
        ++result.only_one;
      }
    }
  return result;
}

TEST(SemiGlobalMatcher, RecoversTwoFrontoParallelPlanes) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SemiGlobalMatcher matcher(smallParams());
  cv::Mat fixed;
  matcher.compute(pair.left, pair.right, fixed);
  ASSERT_EQ(fixed.type(), CV_16SC1);
  ASSERT_EQ(fixed.size(), kSize);
  const cv::Rect background(60, 20, 80, 120);
  const cv::Rect square(pair.square.x + 8, pair.square.y + 8, pair.square.width - 16, pair.square.height - 16);
  EXPECT_GT(shareWithin(fixed, pair.disparity, background, 0.25f), 0.97);
  EXPECT_GT(shareWithin(fixed, pair.disparity, square, 0.25f), 0.97);
}

TEST(SemiGlobalMatcher, RecoversASlantedPlaneToSubPixel) {
  MSF_REQUIRE_AVX2();
  // A smooth random texture; the right view sees column u + d(u) of it with d rising from
  // 10 to 26 px across the image, so that every pixel has a fractional disparity.
  std::mt19937 rng(3);
  cv::Mat texture(kSize.height, kSize.width + 64, CV_32FC1);
  cv::randu(texture, 0.f, 255.f);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  cv::Mat left(kSize, CV_8UC1), right(kSize, CV_8UC1), truth(kSize, CV_32FC1);
  cv::Mat map_x(kSize, CV_32FC1), map_y(kSize, CV_32FC1);
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < kSize.width; ++u) {
      const float d = 10.f + 16.f * static_cast<float>(u) / kSize.width;
      truth.at<float>(v, u) = d;
      map_y.at<float>(v, u) = static_cast<float>(v);
      map_x.at<float>(v, u) = static_cast<float>(u) + 32.f; // left pixel u sees texture column u + 32
    }
  cv::Mat left_f;
  cv::remap(texture, left_f, map_x, map_y, cv::INTER_LINEAR);
  left_f.convertTo(left, CV_8U);
  // The right pixel ur sees the point of the left pixel u with u - d(u) = ur.
  for (int v = 0; v < kSize.height; ++v)
    for (int ur = 0; ur < kSize.width; ++ur) {
      const float u = (static_cast<float>(ur) + 10.f) / (1.f - 16.f / kSize.width);
      map_x.at<float>(v, ur) = u + 32.f;
    }
  cv::Mat right_f;
  cv::remap(texture, right_f, map_x, map_y, cv::INTER_LINEAR);
  right_f.convertTo(right, CV_8U);

  msf::SemiGlobalMatcher matcher(smallParams());
  cv::Mat fixed;
  matcher.compute(left, right, fixed);
  const cv::Rect interior(60, 10, kSize.width - 70, kSize.height - 20);
  EXPECT_GT(shareWithin(fixed, truth, interior, 1.0f), 0.98);
  EXPECT_GT(shareWithin(fixed, truth, interior, 0.5f), 0.85); // sub-pixel, not integer steps
}

TEST(SemiGlobalMatcher, LeavesTheLeftBandEmptyAndHonoursMinDisparity) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SemiGlobalMatcher::Params params = smallParams();
  params.min_disparity = 8;
  params.num_disparities = 32; // 8..39
  msf::SemiGlobalMatcher matcher(params);
  cv::Mat fixed;
  matcher.compute(pair.left, pair.right, fixed);
  const short none = (8 - 1) * 16;
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < 40; ++u)
      ASSERT_EQ(fixed.at<short>(v, u), none) << u << "," << v;
  int valid = 0;
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 40; u < kSize.width; ++u) {
      const short d = fixed.at<short>(v, u);
      ASSERT_TRUE(d == none || (d >= 8 * 16 && d <= 39 * 16)) << d;
      valid += d != none;
    }
  EXPECT_GT(valid, (kSize.width - 40) * kSize.height * 8 / 10);
  EXPECT_GT(shareWithin(fixed, pair.disparity, cv::Rect(60, 20, 80, 120), 0.25f), 0.97);
}

/// A textured plane at 12 px of disparity with a blank cross on it: the rows
/// [rows.start, rows.end) and the columns [cols.start, cols.end) of the plane have no texture.
struct BlankCross {
  cv::Mat left, right;
  cv::Rect crossing; ///< where the bands meet
  static constexpr float kDisparity = 12.f;
};

BlankCross makeBlankCross(cv::Range rows, cv::Range cols) {
  cv::Mat texture(kSize.height, kSize.width + 32, CV_32FC1);
  cv::randu(texture, 0.f, 255.f);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  texture.rowRange(rows).setTo(128.f);
  texture.colRange(cols.start + 16, cols.end + 16).setTo(128.f);
  cv::Mat grey;
  texture.convertTo(grey, CV_8U);
  BlankCross cross;
  // Left pixel u sees texture column u + 16, the right pixel u - 12 too: the plane's disparity.
  cross.left = grey.colRange(16, 16 + kSize.width).clone();
  cross.right = grey.colRange(28, 28 + kSize.width).clone();
  cross.crossing = cv::Rect(cols.start, rows.start, cols.size(), rows.size());
  return cross;
}

TEST(SemiGlobalMatcher, DiagonalPathsMatchWhereRowsAndColumnsSeeNoTexture) {
  MSF_REQUIRE_AVX2();
  // Where the blank bands cross, the rows are blank to both borders and so is the column
  // above: the 3-way paths bring no texture there. The diagonal ones bring the plane's.
  const BlankCross cross = makeBlankCross(cv::Range(60, 84), cv::Range(150, 174));
  cv::Mat truth(kSize, CV_32FC1, cv::Scalar(BlankCross::kDisparity));
  const cv::Rect textured(60, 100, 200, 50);
  cv::Mat three, five;
  msf::SemiGlobalMatcher::Params params = smallParams();
  msf::SemiGlobalMatcher(params).compute(cross.left, cross.right, three);
  params.diagonal_paths = true;
  msf::SemiGlobalMatcher(params).compute(cross.left, cross.right, five);
  // Measured: 0.41 of the crossing within 1 px with three paths, all of it with five.
  EXPECT_LT(shareWithin(three, truth, cross.crossing, 1.f), 0.6);
  EXPECT_GT(shareWithin(five, truth, cross.crossing, 1.f), 0.95);
  EXPECT_GT(shareWithin(three, truth, textured, 0.25f), 0.99);
  EXPECT_GT(shareWithin(five, truth, textured, 0.25f), 0.99);
}

TEST(SemiGlobalMatcher, DiagonalPathsOnImagesBarelyWiderThanTheRange) {
  MSF_REQUIRE_AVX2();
  // One to three matchable columns, fewer rows than strips: the diagonal slots wrap on every
  // row, and every column is a path's first or last.
  for (const int extra : {1, 2, 3})
    for (const int rows : {1, 3, 7}) {
      const cv::Size size(48 + extra, rows);
      cv::Mat left(size, CV_8UC1), right;
      cv::randu(left, 0, 256);
      right = left.clone();
      msf::SemiGlobalMatcher::Params params = smallParams();
      params.diagonal_paths = true;
      cv::Mat fixed;
      msf::SemiGlobalMatcher(params).compute(left, right, fixed);
      ASSERT_EQ(fixed.size(), size);
      const short none = -16;
      EXPECT_EQ(cv::countNonZero(fixed.colRange(0, 48) != none), 0) << extra << "x" << rows;
      for (int v = 0; v < rows; ++v)
        for (int u = 48; u < size.width; ++u) {
          const short d = fixed.at<short>(v, u);
          EXPECT_TRUE(d == none || (d >= 0 && d <= 47 * 16)) << d;
        }
    }
}

TEST(SemiGlobalMatcher, UniquenessRatioRemovesAmbiguousMatches) {
  MSF_REQUIRE_AVX2();
  // A noisy pair: the stricter the ratio, the fewer pixels keep a disparity.
  auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  cv::Mat noise(kSize, CV_8SC1);
  cv::randn(noise, 0, 12);
  cv::add(pair.right, noise, pair.right, cv::noArray(), CV_8U);
  const auto valid_with = [&](int ratio) {
    msf::SemiGlobalMatcher::Params params = smallParams();
    params.uniqueness_ratio = ratio;
    params.speckle_window_size = 0;
    msf::SemiGlobalMatcher matcher(params);
    cv::Mat fixed;
    matcher.compute(pair.left, pair.right, fixed);
    return cv::countNonZero(fixed >= 0);
  };
  const int off = valid_with(0), mild = valid_with(10), strict = valid_with(40);
  EXPECT_GT(off, mild);
  EXPECT_GT(mild, strict);
  EXPECT_GT(strict, 0);
}

TEST(SemiGlobalMatcher, SameResultWhateverTheThreadCountAndOnReuse) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  for (const bool diagonal : {false, true}) {
    msf::SemiGlobalMatcher::Params params = smallParams();
    params.diagonal_paths = diagonal;
    msf::SemiGlobalMatcher matcher(params);
    const int threads = cv::getNumThreads();
    cv::Mat one, two, again;
    cv::setNumThreads(1);
    matcher.compute(pair.left, pair.right, one);
    cv::setNumThreads(threads);
    matcher.compute(pair.left, pair.right, two);
    matcher.compute(pair.left, pair.right, again);
    EXPECT_EQ(cv::countNonZero(one != two), 0) << diagonal;
    EXPECT_EQ(cv::countNonZero(two != again), 0) << diagonal;
  }
}

TEST(SemiGlobalMatcher, BadInputAndParametersAreRejected) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SemiGlobalMatcher matcher(smallParams());
  cv::Mat fixed;
  EXPECT_THROW(matcher.compute(cv::Mat(), pair.right, fixed), msf::InvalidInputError);
  EXPECT_THROW(matcher.compute(pair.left, pair.right(cv::Rect(0, 0, 300, 160)), fixed), msf::InvalidInputError);
  cv::Mat wide, colour;
  pair.left.convertTo(wide, CV_16U);
  EXPECT_THROW(matcher.compute(wide, wide, fixed), msf::InvalidInputError);
  cv::cvtColor(pair.left, colour, cv::COLOR_GRAY2BGR);
  EXPECT_THROW(matcher.compute(colour, colour, fixed), msf::InvalidInputError);
  const auto rejects = [](auto change, const std::string& name) {
    msf::SemiGlobalMatcher::Params params = smallParams();
    change(params);
    try {
      msf::SemiGlobalMatcher m(params);
    } catch (const msf::ConfigError& e) {
      return std::string(e.what()).find("'" + name + "'") != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(rejects([](auto& p) { p.num_disparities = 40; }, "num_disparities"));
  EXPECT_TRUE(rejects([](auto& p) { p.block_size = 4; }, "block_size"));
  EXPECT_TRUE(rejects([](auto& p) { p.p2 = p.p1; }, "p2"));
  EXPECT_TRUE(rejects([](auto& p) { p.pre_filter_cap = 0; }, "pre_filter_cap"));
  EXPECT_TRUE(rejects([](auto& p) { p.uniqueness_ratio = 101; }, "uniqueness_ratio"));
  EXPECT_TRUE(rejects([](auto& p) { p.p1_rise = p.p2; }, "p1_rise"));
  EXPECT_TRUE(rejects([](auto& p) { p.p1_rise = -1; }, "p1_rise"));
}

/// The engine SgbmStereo ran for `engine` and unguided `mode` on `pair`, and its disparity.
std::pair<std::string, cv::Mat> engineAndDisparity(const msf::test::SyntheticPair& pair, const std::string& engine,
                                                   const std::string& mode) {
  msf::SgbmConfig config;
  config.num_disparities_px = 48;
  config.engine = engine;
  config.unguided_mode = mode;
  msf::SgbmStereo stereo(config);
  stereo.setInputImages(pair.left, pair.right);
  stereo.computeDisparity();
  return {stereo.getEngineUsed(), stereo.getDisparity().clone()};
}

TEST(SemiGlobalMatcher, WithoutAvx2SgbmStereoFallsBackToOpenCvForItsModes) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  const auto [opencv_engine, opencv] = engineAndDisparity(pair, "opencv", "sgbm_3way");
  EXPECT_EQ(opencv_engine, "opencv");
  cv::Mat ground_portable;
  {
    const Avx2Disabled off;
    EXPECT_FALSE(msf::SemiGlobalMatcher::usesAvx2());
    const auto [engine, disparity] = engineAndDisparity(pair, "native", "sgbm_3way");
    EXPECT_EQ(engine, "opencv");
    EXPECT_EQ(cv::countNonZero(disparity != opencv), 0);
    // OpenCV has no ground_3way: the portable kernel runs it.
    const auto [ground_engine, ground] = engineAndDisparity(pair, "native", "ground_3way");
    EXPECT_EQ(ground_engine, "native");
    ground_portable = ground;
  }
  if (msf::SemiGlobalMatcher::usesAvx2()) {
    EXPECT_EQ(engineAndDisparity(pair, "native", "sgbm_3way").first, "native");
    EXPECT_EQ(cv::countNonZero(engineAndDisparity(pair, "native", "ground_3way").second != ground_portable), 0);
  }
  // sgbm (five paths) runs natively where the AVX2 kernel does; hh and hh4 on OpenCV.
  EXPECT_EQ(engineAndDisparity(pair, "native", "sgbm").first, msf::SemiGlobalMatcher::usesAvx2() ? "native" : "opencv");
  EXPECT_EQ(engineAndDisparity(pair, "native", "hh").first, "opencv");
  // Engine opencv runs its 3-way for ground_3way.
  const auto [opencv_ground_engine, opencv_ground] = engineAndDisparity(pair, "opencv", "ground_3way");
  EXPECT_EQ(opencv_ground_engine, "opencv");
  EXPECT_EQ(cv::countNonZero(opencv_ground != opencv), 0);
}

TEST(SemiGlobalMatcher, SgbmStereoMatchesTheLeftBorderWithTheNativeEngine) {
  MSF_REQUIRE_AVX2();
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SgbmConfig config;
  config.num_disparities_px = 48;
  msf::SgbmStereo plain(config);
  plain.setInputImages(pair.left, pair.right);
  plain.computeDisparity();
  ASSERT_EQ(plain.getEngineUsed(), "native");
  EXPECT_EQ(cv::countNonZero(plain.getDisparity().colRange(0, 48) > 0.f), 0);
  config.match_left_border = true;
  msf::SgbmStereo bordered(config);
  bordered.setInputImages(pair.left, pair.right);
  bordered.computeDisparity();
  const cv::Mat band = bordered.getDisparity()(cv::Rect(16, 20, 24, 120));
  EXPECT_GT(cv::countNonZero(cv::abs(band - 12.f) < 0.25f), band.total() * 9 / 10);
}

/// The grey pair of KITTI odometry 04, frame 0.
struct GreyPair {
  cv::Mat left, right;
};

GreyPair odometryFrame0() {
  const std::string seq = msf::test::kittiDir() + "/odometry/sequences/04/";
  return {msf::readImage(seq + "image_0/000000.png", cv::IMREAD_GRAYSCALE),
          msf::readImage(seq + "image_1/000000.png", cv::IMREAD_GRAYSCALE)};
}

/// OpenCV's StereoSGBM in `mode` with the native matcher's `params` (block 5).
cv::Mat openCvDisparity(const GreyPair& pair, const msf::SemiGlobalMatcher::Params& params, int mode) {
  cv::Mat disparity;
  cv::StereoSGBM::create(0, params.num_disparities, 5, params.p1, params.p2, params.disp12_max_diff,
                         params.pre_filter_cap, params.uniqueness_ratio, params.speckle_window_size,
                         params.speckle_range, mode)
      ->compute(pair.left, pair.right, disparity);
  return disparity;
}

TEST(SemiGlobalMatcherKitti, AgreesWithOpenCvOnAnOdometryFrame) {
  MSF_REQUIRE_KITTI();
  MSF_REQUIRE_AVX2();
  const GreyPair pair = odometryFrame0();
  for (const int disparities : {128, 80}) {
    msf::SemiGlobalMatcher::Params params;
    params.num_disparities = disparities;
    cv::Mat native;
    msf::SemiGlobalMatcher(params).compute(pair.left, pair.right, native);
    const Agreement agreement = compare(native, openCvDisparity(pair, params, cv::StereoSGBM::MODE_SGBM_3WAY));
    // Measured on frames 0, 5, 9: <= 0.03 % of the common pixels more than 1 px apart,
    // ~0.1 % matched by one only (ties, and OpenCV's strip warm-up from the strip's first row).
    ASSERT_GT(agreement.both, 350000);
    EXPECT_LT(static_cast<double>(agreement.apart) / agreement.both, 0.002) << disparities;
    EXPECT_LT(static_cast<double>(agreement.only_one) / agreement.both, 0.01) << disparities;
  }
}

TEST(SemiGlobalMatcherKitti, DiagonalPathsAgreeWithOpenCvsFivePathMode) {
  MSF_REQUIRE_KITTI();
  MSF_REQUIRE_AVX2();
  const GreyPair pair = odometryFrame0();
  msf::SemiGlobalMatcher::Params params;
  const cv::Mat opencv = openCvDisparity(pair, params, cv::StereoSGBM::MODE_SGBM);
  cv::Mat five, three;
  msf::SemiGlobalMatcher(params).compute(pair.left, pair.right, three);
  params.diagonal_paths = true;
  msf::SemiGlobalMatcher(params).compute(pair.left, pair.right, five);
  // Measured on frames 0, 5, 9: <= 0.16 % of the common pixels more than 1 px apart and
  // <= 1.3 % matched by one only (OpenCV runs MODE_SGBM's paths over the whole image, we over
  // strips warmed up as in 3-way); three paths differ from it on 2.1-2.4 % and 5.2-6.7 %.
  const Agreement agreement = compare(five, opencv), without = compare(three, opencv);
  ASSERT_GT(agreement.both, 350000);
  EXPECT_LT(static_cast<double>(agreement.apart) / agreement.both, 0.003);
  EXPECT_LT(static_cast<double>(agreement.only_one) / agreement.both, 0.02);
  EXPECT_GT(static_cast<double>(without.apart) / without.both, 0.015);
}

} // namespace
