// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Protocol 4's transient pixels (ReconstructionEvaluation::addScan) against a synthetic street's
// moving cars: what the scans call transient is, nearly all of it, a moving car.
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/io/pinhole_camera.h>
#include <msf/io/sequence.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/synthetic_generator.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <iostream>

using namespace msf;

namespace {

/// Every 8th row of the exact depth: sparse, as held-out rings are.
cv::Mat everyEighthRow(const cv::Mat& depth) {
  cv::Mat sparse(depth.size(), CV_32FC1, cv::Scalar(0.f));
  for (int v = 0; v < depth.rows; v += 8)
    depth.row(v).copyTo(sparse.row(v));
  return sparse;
}

/// Protocol 4 over the street's frames, scored against their own truth; with the street's
/// moving masks or without them (as on real frames, where only the scans say what moved).
ReconstructionScore scoreOfTheTruth(const Sequence& street, const synthetic::GroundTruth& truth, bool with_masks) {
  const Calibration& calibration = street.calibration();
  ReconstructionEvaluation evaluation(PinholeCamera::fromCalibration(calibration, 0), calibration.focalBaseline(),
                                      40.0);
  for (std::size_t i = 0; i < street.size(); ++i) {
    const Eigen::Isometry3d& T_world_cam = street.poses()[i];
    const cv::Mat depth = everyEighthRow(truth.depth(i));
    evaluation.addGroundTruth(i, T_world_cam, depth, with_masks ? truth.movingMask(i) : cv::Mat());
    evaluation.addScan(i, T_world_cam * calibration.T_cam0_velo,
                       ScanFreeSpace(*street.loadScan(i), calibration.lidar.sweeping));
    evaluation.scoreDepth("truth", i, depth);
  }
  return evaluation.scores().at(0);
}

} // namespace

TEST(TransientReturns, AreTheMovingCarsOfTheStreet) {
  test::TempDir dir;
  synthetic::SyntheticConfig config;
  config.frames = 8;
  synthetic::SyntheticGenerator(config).writeDataset(dir.file("street"));
  const Sequence street(dir.file("street"));
  const synthetic::GroundTruth truth(street.groundTruthDir());

  const ReconstructionScore masked = scoreOfTheTruth(street, truth, true);
  const ReconstructionScore unmasked = scoreOfTheTruth(street, truth, false);
  const std::size_t moving = masked.moving_within_range.gt_pixels;
  const std::size_t transient = unmasked.transient_within_range.gt_pixels;
  // Without the masks, the moving pixels are among the static ones; with them, the transient
  // pixels left are static surfaces the scans called transient.
  const std::size_t on_cars = transient - masked.transient_within_range.gt_pixels;
  std::cout << "transient pixels on moving cars: " << on_cars << " of " << transient
            << "; moving pixels transient: " << on_cars << " of " << moving << "\n";
  ASSERT_GT(moving, 500u) << "the street's frames show no moving car";
  EXPECT_GT(on_cars, 0.95 * transient) << on_cars << " of " << transient << " transient pixels on moving cars";
  EXPECT_GT(on_cars, 0.85 * moving) << on_cars << " of " << moving << " moving pixels transient";
  // The truth scored against itself: right everywhere, transient or not.
  EXPECT_DOUBLE_EQ(unmasked.transient_within_range.d1_all, 0.0);
  EXPECT_DOUBLE_EQ(unmasked.lasting_within_range.coverage, 1.0);
}
