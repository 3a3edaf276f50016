// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The LiDAR and stereo checked against each other: a right rig agrees, a wrong one is named.
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/rig_agreement.h>
#include <msf/pipeline/run_report.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

TEST(RigAgreement, TheShareCountsPixelsWithARealReturnAndAStereoDepth) {
  cv::Mat lidar(2, 3, CV_32FC1, cv::Scalar(10.f)), distance(2, 3, CV_32FC1, cv::Scalar(0.f));
  cv::Mat stereo(2, 3, CV_32FC1, cv::Scalar(10.5f)); // 5 % off: agrees
  stereo.at<float>(0, 0) = 12.f;                      // 20 % off
  stereo.at<float>(0, 1) = 0.f;                       // no stereo depth: not counted
  distance.at<float>(1, 2) = 3.f;                     // interpolated, not a return: not counted
  stereo.at<float>(1, 2) = 30.f;
  EXPECT_DOUBLE_EQ(msf::lidarStereoDisagreement(lidar, distance, stereo), 1.0 / 4.0);
  EXPECT_TRUE(std::isnan(msf::lidarStereoDisagreement(lidar, distance, cv::Mat(2, 3, CV_32FC1, cv::Scalar(0.f)))));
  const double nan = std::nan("");
  EXPECT_EQ(msf::rigDisagreementWarning({0.03, 0.5, 0.04, nan}), ""); // the median, NaN skipped
  const std::string warning = msf::rigDisagreementWarning({0.5, 0.45, 0.04, nan});
  EXPECT_NE(warning.find("disagree by more than 10 % on 45 % of the pixels both measure"), std::string::npos)
      << warning;
  EXPECT_NE(warning.find("not its inverse"), std::string::npos) << warning;
  EXPECT_EQ(msf::rigDisagreementWarning({nan}), "");
  // A row longer than a vector register, with a tail: every 3rd pixel 20 % off.
  cv::Mat wide_lidar(1, 37, CV_32FC1, cv::Scalar(8.f)), wide_stereo = wide_lidar.clone();
  for (int u = 0; u < 37; u += 3)
    wide_stereo.at<float>(0, u) = 9.6f;
  EXPECT_DOUBLE_EQ(msf::lidarStereoDisagreement(wide_lidar, cv::Mat::zeros(1, 37, CV_32FC1), wide_stereo), 13.0 / 37);
  // A result no fusion ran on measured nothing: NaN, which the median skips, not a share of 0.
  EXPECT_TRUE(std::isnan(msf::FrameResult().lidar_stereo_disagreement));
  EXPECT_TRUE(std::isnan(msf::RunReport::FrameRow().lidar_stereo_disagreement));
}

TEST_F(PipelineTest, ARightRigAgreesAndAnInvertedExtrinsicIsWarnedOf) {
  const msf::Sequence sequence(dataset());
  const msf::Frame frame = sequence.load(0);
  msf::Reconstructor right(sequence.calibration(), msf::PipelineConfig{});
  const double agreed = right.computeDepth(frame).lidar_stereo_disagreement;
  EXPECT_LT(agreed, 0.1);
  msf::Calibration inverted = sequence.calibration();
  inverted.T_cam0_velo = inverted.T_cam0_velo.inverse(); // the camera-to-LiDAR transform given for its inverse
  msf::Reconstructor wrong(inverted, msf::PipelineConfig{});
  const double disagreed = wrong.computeDepth(frame).lidar_stereo_disagreement;
  EXPECT_GT(disagreed, msf::kRigDisagreementWarning) << "right rig: " << agreed;
  EXPECT_NE(msf::rigDisagreementWarning({disagreed}), "");
}
