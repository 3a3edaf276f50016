// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/odometry_metrics.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

/// Camera poses along +z (KITTI's forward), `step` metres apart.
msf::PoseList straight(std::size_t n, double step) {
  msf::PoseList poses;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0, 0, step * static_cast<double>(i));
    poses.push_back(T);
  }
  return poses;
}

TEST(OdometryMetrics, ScaleErrorOnALongDriveIsTheDevkitsTranslationError) {
  // 1000 m in 1 m steps, the estimate 1 % too long: every devkit segment is 1 % off, no rotation.
  const msf::PoseList reference = straight(1001, 1.0), estimate = straight(1001, 1.01);
  const msf::OdometryMetrics m = msf::evaluateOdometry(estimate, reference);
  EXPECT_TRUE(m.devkit_lengths);
  EXPECT_EQ(m.segment_lengths_m.size(), 8u);
  EXPECT_DOUBLE_EQ(m.path_length_m, 1000.0);
  // First frames 0, 10, ...: a segment of length L ends at the first frame farther than L,
  // i.e. L + 1 frames on; 1000 - L - 1 frames remain for its start.
  std::size_t expected = 0;
  for (int length = 100; length <= 800; length += 100)
    for (int first = 0; first <= 1000; first += 10)
      expected += first + length + 1 <= 1000;
  EXPECT_EQ(m.segments, expected);
  // The error of a segment of L metres ending L + 1 frames on is 0.01 (L + 1) / L.
  double sum = 0;
  for (int length = 100; length <= 800; length += 100)
    for (int first = 0; first <= 1000; first += 10)
      if (first + length + 1 <= 1000)
        sum += 0.01 * (length + 1.0) / length;
  EXPECT_NEAR(m.translation_error_pct, 100.0 * sum / expected, 1e-9);
  EXPECT_NEAR(m.rotation_error_deg_per_m, 0.0, 1e-9);
  EXPECT_NEAR(m.end_drift_m, 10.0, 1e-9);
  EXPECT_NEAR(m.end_drift_pct, 1.0, 1e-9);
  // ATE: position i is off by 0.01 i.
  double sum2 = 0;
  for (int i = 0; i <= 1000; ++i)
    sum2 += 1e-4 * i * i;
  EXPECT_NEAR(m.ate_rmse_m, std::sqrt(sum2 / 1001), 1e-9);
  EXPECT_NEAR(m.ate_max_m, 10.0, 1e-9);
}

TEST(OdometryMetrics, AShortDriveUsesEighthsOfItsLengthAndTheFirstPoseIsAligned) {
  // 12 m (KITTI 04's ten frames): the estimate starts elsewhere and heads 1 degree off.
  const msf::PoseList reference = straight(10, 1.3333);
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  offset.translation() << 5, -2, 7;
  msf::PoseList estimate;
  for (const auto& T : reference)
    estimate.push_back(offset * T);
  const msf::OdometryMetrics m = msf::evaluateOdometry(estimate, reference);
  EXPECT_FALSE(m.devkit_lengths);
  ASSERT_EQ(m.segment_lengths_m.size(), 7u);
  EXPECT_NEAR(m.segment_lengths_m.front(), 12.0 / 8, 1e-3);
  EXPECT_NEAR(m.segment_lengths_m.back(), 7 * 12.0 / 8, 1e-3);
  // A rigid offset of the whole trajectory is no error once the first poses are aligned.
  EXPECT_NEAR(m.ate_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(m.end_drift_m, 0.0, 1e-9);
  EXPECT_NEAR(m.translation_error_pct, 0.0, 1e-9);
  EXPECT_NEAR(m.rotation_error_deg_per_m, 0.0, 1e-7);
  EXPECT_GT(m.segments, 7u); // every frame starts segments

  // Heading 1 degree off from the start: the last position is 12 m * sin(1 deg) aside.
  msf::PoseList turned;
  for (const auto& T : reference) {
    Eigen::Isometry3d U = T;
    U.translation() = offset.linear() * T.translation();
    turned.push_back(U);
  }
  const msf::OdometryMetrics t = msf::evaluateOdometry(turned, reference);
  EXPECT_NEAR(t.end_drift_m, 2 * 12.0 * std::sin(0.5 * M_PI / 180.0), 1e-3);
  EXPECT_NEAR(t.end_drift_pct, 100 * 2 * std::sin(0.5 * M_PI / 180.0), 1e-2);
  EXPECT_NEAR(t.rotation_error_deg_per_m, 0.0, 1e-7); // the orientations agree
  EXPECT_NEAR(t.end_rotation_error_deg, 0.0, 1e-6);
}

TEST(OdometryMetrics, RotationErrorIsDegreesPerMetre) {
  // The estimate yaws 0.01 degrees more per metre than the reference and moves as it does.
  const msf::PoseList longer_ref = straight(12, 10.0);
  msf::PoseList longer_est = longer_ref;
  for (std::size_t i = 0; i < longer_est.size(); ++i)
    longer_est[i].linear() =
        Eigen::AngleAxisd(0.01 * 10.0 * i * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const msf::OdometryMetrics l = msf::evaluateOdometry(longer_est, longer_ref);
  EXPECT_TRUE(l.devkit_lengths); // 110 m: the devkit's 100 m fits
  ASSERT_EQ(l.segments, 1u);      // frame 0 to frame 11 (the first beyond 100 m), over a length of 100 m
  EXPECT_NEAR(l.translation_error_pct, 0.0, 1e-9);
  EXPECT_NEAR(l.rotation_error_deg_per_m, 0.01 * 110.0 / 100.0, 1e-9);
}

TEST(OdometryMetrics, MismatchedOrStillTrajectoriesAreErrors) {
  EXPECT_THROW(msf::evaluateOdometry(straight(5, 1.0), straight(6, 1.0)), msf::InvalidInputError);
  EXPECT_THROW(msf::evaluateOdometry(straight(1, 1.0), straight(1, 1.0)), msf::InvalidInputError);
  EXPECT_THROW(msf::evaluateOdometry(straight(5, 1.0), straight(5, 0.0)), msf::InvalidInputError);
}

} // namespace
