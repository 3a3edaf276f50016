// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/disparity_metrics.h>
#include <msf/io/image_io.h>

#include "test_support.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace {

cv::Mat row(std::initializer_list<float> values) {
  cv::Mat m(1, static_cast<int>(values.size()), CV_32FC1);
  int i = 0;
  for (float v : values)
    m.at<float>(0, i++) = v;
  return m;
}

TEST(DisparityMetrics, HandMadePixels) {
  //                 gt:   10    10    100   100   50    0     20
  //                 est:  13.5  12    104   106   0     30    NaN
  // errors:               3.5   2     4     6     miss  (no gt) miss
  // bad (> 3 and > 5 %):  yes   no    no    yes   yes         yes
  const cv::Mat gt = row({10, 10, 100, 100, 50, 0, 20});
  const cv::Mat est = row({13.5f, 12, 104, 106, 0, 30, std::nanf("")});
  const auto e = msf::evaluateDisparity(gt, est);
  EXPECT_FALSE(e.has_object_map);
  EXPECT_EQ(e.all.gt_pixels, 6u);
  EXPECT_EQ(e.all.estimated, 4u);
  EXPECT_EQ(e.all.bad, 4u);
  EXPECT_EQ(e.all.bad_estimated, 2u);
  EXPECT_NEAR(e.all.d1(), 4.0 / 6.0, 1e-12);
  EXPECT_NEAR(e.all.d1Estimated(), 0.5, 1e-12);
  EXPECT_NEAR(e.all.density(), 4.0 / 6.0, 1e-12);
  EXPECT_NEAR(e.all.meanAbsError(), (3.5 + 2 + 4 + 6) / 4.0, 1e-6); // eq. 8 over estimates
  // Without an object map everything is background.
  EXPECT_EQ(e.background.gt_pixels, 6u);
  EXPECT_EQ(e.foreground.gt_pixels, 0u);
}

TEST(DisparityMetrics, ObjectMapSplitsBackgroundAndForeground) {
  const cv::Mat gt = row({10, 10, 100, 100});
  const cv::Mat est = row({13.5f, 12, 104, 106});
  cv::Mat objects = (cv::Mat_<std::uint8_t>(1, 4) << 0, 0, 7, 7);
  const auto e = msf::evaluateDisparity(gt, est, objects);
  EXPECT_TRUE(e.has_object_map);
  EXPECT_EQ(e.background.gt_pixels, 2u);
  EXPECT_EQ(e.background.bad, 1u);
  EXPECT_EQ(e.foreground.gt_pixels, 2u);
  EXPECT_EQ(e.foreground.bad, 1u);
  EXPECT_NEAR(e.foreground.meanAbsError(), 5.0, 1e-6);
  EXPECT_EQ(e.all.bad, 2u);
  // 16-bit maps work the same.
  cv::Mat objects16;
  objects.convertTo(objects16, CV_16U);
  EXPECT_EQ(msf::evaluateDisparity(gt, est, objects16).foreground.bad, 1u);
}

TEST(DisparityMetrics, BackgroundInterpolationAsTheDevkit) {
  cv::Mat d(4, 6, CV_32FC1, cv::Scalar(0));
  // row 1: 0 5 0 0 8 0 -> 5 5 5 5 8 8 (gap takes the smaller end, ends extrapolate)
  d.at<float>(1, 1) = 5;
  d.at<float>(1, 4) = 8;
  // row 3: a single value fills the row; row 2 (between filled rows) stays empty, row 0
  // (above the first filled row) copies row 1.
  d.at<float>(3, 2) = 2;
  const cv::Mat f = msf::interpolateBackground(d);
  const float expected1[] = {5, 5, 5, 5, 8, 8};
  for (int u = 0; u < 6; ++u) {
    EXPECT_EQ(f.at<float>(1, u), expected1[u]) << u;
    EXPECT_EQ(f.at<float>(0, u), expected1[u]) << u;
    EXPECT_EQ(f.at<float>(2, u), 0.f) << u;
    EXPECT_EQ(f.at<float>(3, u), 2.f) << u;
  }
  // With the option, a missing estimate is judged by its interpolated value.
  const cv::Mat gt = row({10, 10, 10});
  const cv::Mat est = row({10, 0, 20});
  msf::DisparityEvalOptions options;
  EXPECT_EQ(msf::evaluateDisparity(gt, est, cv::Mat(), options).all.bad, 2u); // missing + 10 px off
  options.interpolate_background = true;
  const auto e = msf::evaluateDisparity(gt, est, cv::Mat(), options);
  EXPECT_EQ(e.all.bad, 1u); // the gap took min(10, 20) = 10
  EXPECT_EQ(e.all.estimated, 2u);
  EXPECT_EQ(e.all.evaluated, 3u);
  EXPECT_NEAR(e.all.meanAbsError(), 10.0 / 3.0, 1e-6);
}

TEST(DisparityMetrics, AccumulatesFramesByPixels) {
  msf::DisparityEvaluation total;
  total += msf::evaluateDisparity(row({10, 10}), row({20, 10}));
  total += msf::evaluateDisparity(row({10, 10, 10, 10}), row({10, 10, 10, 10}));
  EXPECT_EQ(total.all.gt_pixels, 6u);
  EXPECT_NEAR(total.all.d1(), 1.0 / 6.0, 1e-12);
}

TEST(DisparityMetrics, BadInputNamesTheImage) {
  const cv::Mat gt = row({10, 10});
  EXPECT_NE(msf::test::errorOf([&] { msf::evaluateDisparity(gt, row({1, 2, 3})); }).find("estimated disparity is 3x1 but the ground truth is 2x1"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([&] { msf::evaluateDisparity(gt, cv::Mat(1, 2, CV_16U)); }).find("estimated disparity"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([&] { msf::evaluateDisparity(gt, gt, cv::Mat(1, 3, CV_8U)); }).find("object map is 3x1"),
            std::string::npos);
  EXPECT_THROW(msf::interpolateBackground(cv::Mat(2, 2, CV_8U)), msf::InvalidInputError);
}

// The devkit's sample: D1 of disp_est against disp_gt is 13.62 % (protocol 1, docs/design.md).
TEST(DisparityMetricsKitti, DevkitSampleD1) {
  MSF_REQUIRE_KITTI();
  const std::string dir = msf::test::kittiDir() + "/stereo2015_devkit/";
  const cv::Mat gt = msf::readKittiDisparityPng(dir + "disp_gt.png");
  const cv::Mat est = msf::readKittiDisparityPng(dir + "disp_est.png");
  const auto e = msf::evaluateDisparity(gt, est);
  EXPECT_NEAR(100.0 * e.all.d1(), 13.62, 0.005);
  EXPECT_GT(e.all.gt_pixels, 100000u);
  msf::DisparityEvalOptions options;
  options.interpolate_background = true;
  EXPECT_NEAR(100.0 * msf::evaluateDisparity(gt, est, cv::Mat(), options).all.d1(), 13.62, 0.005);
}

TEST(EvalDisparityTool, PrintsTheDevkitSampleD1) {
  MSF_REQUIRE_KITTI();
  const std::string dir = msf::test::kittiDir() + "/stereo2015_devkit/";
  const auto r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + dir + "disp_est.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("13.62 %"), std::string::npos) << r.out;
}

TEST(EvalDisparityTool, ObjectMapRowsAndBadInput) {
  MSF_REQUIRE_KITTI();
  const std::string dir = msf::test::kittiDir() + "/stereo2015_devkit/";
  msf::test::TempDir tmp;
  // An object map: the right half of the image is foreground.
  const cv::Mat gt = msf::readKittiDisparityPng(dir + "disp_gt.png");
  cv::Mat objects(gt.size(), CV_8UC1, cv::Scalar(0));
  objects.colRange(gt.cols / 2, gt.cols).setTo(1);
  cv::imwrite(tmp.file("obj.png"), objects);
  auto r = msf::test::runTool("msf_eval_disparity",
                              dir + "disp_gt.png " + dir + "disp_est.png -obj_map " + tmp.file("obj.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("background"), std::string::npos);
  EXPECT_NE(r.out.find("foreground"), std::string::npos);
  EXPECT_NE(r.out.find("13.62 %"), std::string::npos) << r.out;

  // A missing estimate file.
  r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + tmp.file("none.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_eval_disparity: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("none.png"), std::string::npos) << r.err;
  // An estimate of another size.
  cv::imwrite(tmp.file("small.png"), cv::Mat(10, 10, CV_16UC1, cv::Scalar(256)));
  r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + tmp.file("small.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("is 10x10 but ground truth"), std::string::npos) << r.err;
  // An 8-bit image is not a KITTI disparity PNG.
  cv::imwrite(tmp.file("eight.png"), objects);
  r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + tmp.file("eight.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("16-bit"), std::string::npos) << r.err;
  // An object map of another size, and an unknown option.
  r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + dir + "disp_est.png -obj_map " + tmp.file("small.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("object map"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_eval_disparity", dir + "disp_gt.png " + dir + "disp_est.png -objmap x");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("unknown option '-objmap'"), std::string::npos) << r.err;
}

} // namespace
