// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Where a fusion loses to the better of its inputs, on hand-made pixels.
#include <msf/common/exceptions.h>
#include <msf/evaluation/fusion_loss.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

cv::Mat row(std::initializer_list<float> values) { return cv::Mat(cv::Mat_<float>(values)).reshape(1, 1).clone(); }

// f B = 100: the truth at 10 m is a disparity of 10 px, and D1 calls an error over 3 px bad.
constexpr double kFocalBaseline = 100.0;

TEST(FusionLoss, CountsThePixelsLostWhereAnInputWasRightByWhatTheFusionGave) {
  // Pixels: first right and the fusion gave the second / between / none / elsewhere; second
  // right and the fusion gave the first; both right; both wrong; the fusion right; no truth;
  // first right, second missing, fusion none; only the first right and the fusion gave it; only
  // the second right and the fusion gave it.
  const cv::Mat gt = row({10, 10, 10, 10, 10, 10, 10, 10, 0, 10, 10, 10});
  const cv::Mat a = row({10.2f, 10, 10, 10, 20, 10, 20, 20, 10, 10, 10, 20});
  const cv::Mat b = row({5, 5, 5, 5, 10, 9.9f, 5, 5, 5, 0, 5, 10});
  const cv::Mat f = row({5.02f, 7, 0, 20, 20, 4, 5, 10.1f, 5, 0, 10.05f, 10});
  msf::FusionLoss loss;
  loss.add(gt, a, b, f, kFocalBaseline, msf::D1Threshold());
  EXPECT_EQ(loss.ground_truth, 11u);
  EXPECT_EQ(loss.first_right[msf::FusionLoss::TheOtherInput], 1u);
  EXPECT_EQ(loss.first_right[msf::FusionLoss::Between], 1u);
  EXPECT_EQ(loss.first_right[msf::FusionLoss::Nothing], 2u);
  EXPECT_EQ(loss.first_right[msf::FusionLoss::Elsewhere], 1u);
  EXPECT_EQ(loss.second_right[msf::FusionLoss::TheOtherInput], 1u);
  EXPECT_EQ(loss.second_right[msf::FusionLoss::Between] + loss.second_right[msf::FusionLoss::Nothing] +
                loss.second_right[msf::FusionLoss::Elsewhere],
            0u);
  EXPECT_EQ(loss.both_right, 1u);
  EXPECT_EQ(loss.lost(), 7u);
  EXPECT_EQ(loss.gave_first_right, 1u);
  EXPECT_EQ(loss.gave_second_right, 1u);

  // A second frame adds to the counts.
  loss.add(gt, a, b, f, kFocalBaseline, msf::D1Threshold());
  EXPECT_EQ(loss.ground_truth, 22u);
  EXPECT_EQ(loss.lost(), 14u);

  const std::string table = msf::formatFusionLoss({{"fused", loss}}, "lidar", "stereo");
  EXPECT_NE(table.find("lidar right"), std::string::npos) << table;
  EXPECT_NE(table.find("stereo right"), std::string::npos) << table;
  // 14 of 22 lost; first right: 2, 2, 4, 2 of 22; second right: 2 of 22; both: 2 of 22.
  EXPECT_NE(table.find("\nfused                63.64%   9.09 / 9.09 / 18.18 / 9.09     9.09 / 0.00 / 0.00 / 0.00      "
                       "9.09\n"),
            std::string::npos)
      << table;
  // Giving the first input: right at 2 of 22 pixels, wrong at 2 (only the second right); the same
  // for the second.
  EXPECT_NE(table.find("gave lidar               gave stereo\n"
                       "fused                9.09 / 9.09              9.09 / 9.09\n"),
            std::string::npos)
      << table;
}

TEST(FusionLoss, ImagesOfAnotherSizeOrTypeAreErrors) {
  const cv::Mat ok(4, 5, CV_32FC1, cv::Scalar(1));
  msf::FusionLoss loss;
  EXPECT_THROW(loss.add(ok, ok, ok, cv::Mat(4, 6, CV_32FC1), kFocalBaseline, {}), msf::InvalidInputError);
  EXPECT_THROW(loss.add(ok, cv::Mat(4, 5, CV_64FC1), ok, ok, kFocalBaseline, {}), msf::InvalidInputError);
  EXPECT_THROW(loss.add(cv::Mat(), ok, ok, ok, kFocalBaseline, {}), msf::InvalidInputError);
  EXPECT_EQ(loss.ground_truth, 0u);
}

} // namespace
