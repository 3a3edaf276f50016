// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A GPS/INS's poses as a prior of the scan-to-map registration: the scans correct what they
// pin down (a drifting heading), the prior holds what they cannot (a tunnel's axis, no scan).
#include "box_scene.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/registration/scan_to_map_icp.h>
#include <msf/registration/voxel_downsample.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using msf::test::Box;
using msf::test::scanBoxes;
using msf::test::sensorPose;

double yawDeg(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d x = T.linear().col(0);
  return std::atan2(x.y(), x.x()) * 180.0 / M_PI;
}

msf::LidarOdometry::Config snapshots() {
  msf::LidarOdometry::Config config;
  config.deskew = "none";
  return config;
}

/// A straight tunnel along x: floor, walls and ceiling without a feature along it.
std::vector<Box> tunnel() {
  return {{{-100, -6, -1}, {300, 6, 0}},
          {{-100, -7, 0}, {300, -5, 6}},
          {{-100, 5, 0}, {300, 7, 6}},
          {{-100, -6, 6}, {300, 6, 7}}};
}

/// The sensor's motion between consecutive poses, in its own frame.
Eigen::Isometry3d motion(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) { return from.inverse() * to; }

TEST(PosePrior, WithoutPairsTheRegistrationIsThePrior) {
  msf::LocalMap empty(1.0, 10);
  msf::PosePrior prior;
  prior.T_world_sensor = sensorPose(3.0, 0.5, 0.1);
  msf::IcpSettings settings;
  settings.prior = &prior;
  const msf::PointList points = scanBoxes(msf::test::streetOfBoxes(), sensorPose(0.0), 1);
  const msf::IcpResult result = msf::alignScanToMap(points, empty, sensorPose(2.0), settings);
  EXPECT_TRUE(result.T_world_sensor.isApprox(prior.T_world_sensor, 1e-6));
  EXPECT_EQ(result.correspondences, 0u);
  settings.prior = nullptr; // without one: an error, as before
  EXPECT_THROW(msf::alignScanToMap(points, empty, sensorPose(2.0), settings), msf::InvalidInputError);
}

TEST(PosePrior, TheScansCorrectADriftingHeading) {
  // 25 frames at 1.2 m a frame down the street of boxes; the measured poses' heading drifts by
  // 0.08 degrees a frame (2 degrees in all) and their position wanders by decimetres. The
  // refined poses stay as near the truth as the odometry's without a prior.
  const auto boxes = msf::test::streetOfBoxes();
  msf::LidarOdometry refined(snapshots()), alone(snapshots());
  Eigen::Isometry3d measured_last = sensorPose(0.0);
  double worst_yaw = 0.0, worst_position = 0.0, alone_position = 0.0, measured_yaw = 0.0;
  for (int k = 0; k < 25; ++k) {
    const Eigen::Isometry3d truth = sensorPose(1.2 * k, 0.3 * std::sin(0.2 * k));
    const Eigen::Isometry3d measured = sensorPose(1.2 * k + 0.3 * std::sin(0.3 * k),
                                                  0.3 * std::sin(0.2 * k) + 0.2 * std::sin(0.5 * k), 0.08 * k * M_PI / 180.0);
    const Eigen::Isometry3d measured_motion = motion(measured_last, measured);
    measured_last = measured;
    const msf::PointList scan = scanBoxes(boxes, truth, 10 + k);
    const Eigen::Isometry3d relative_truth = sensorPose(0.0).inverse() * truth; // the first scan is the world
    const Eigen::Isometry3d error = relative_truth.inverse() * refined.registerPoints(scan, "scan", &measured_motion);
    worst_yaw = std::max(worst_yaw, std::abs(yawDeg(error)));
    worst_position = std::max(worst_position, error.translation().norm());
    alone_position = std::max(alone_position, (relative_truth.inverse() * alone.registerPoints(scan)).translation().norm());
    measured_yaw = std::abs(yawDeg(truth.inverse() * measured));
  }
  EXPECT_NEAR(measured_yaw, 1.92, 1e-6);
  EXPECT_LT(worst_yaw, 0.15);
  EXPECT_LT(worst_position, 1.5 * alone_position + 0.01) << "the odometry alone: " << alone_position;
  EXPECT_LT(worst_position, 0.15); // the measured positions err by up to 0.5 m
}

TEST(PosePrior, ATunnelKeepsThePriorsMotionAlongItsAxis) {
  const auto boxes = tunnel();
  const msf::PointList first = scanBoxes(boxes, sensorPose(0.0), 1);
  // Without a prior the tunnel's axis is free: an error that names it.
  msf::LidarOdometry alone(snapshots());
  EXPECT_THROW(alone.registerPoints(first), msf::InvalidInputError);

  // With one, the scans hold the cross-section (the prior's 0.2 m sideways error is corrected)
  // and the prior's 1.1 m a frame, 0.1 m more than the truth, holds the axis.
  msf::LidarOdometry odometry(snapshots());
  Eigen::Isometry3d measured_last = sensorPose(0.0);
  for (int k = 0; k < 6; ++k) {
    const Eigen::Isometry3d truth = sensorPose(1.0 * k);
    const Eigen::Isometry3d measured = sensorPose(1.1 * k, k == 0 ? 0.0 : 0.2);
    const Eigen::Isometry3d measured_motion = motion(measured_last, measured);
    // The first scan's measured motion marks it as measured (its pose is the world's origin).
    const Eigen::Isometry3d estimate = odometry.registerPoints(scanBoxes(boxes, truth, 20 + k), "scan", &measured_motion);
    measured_last = measured;
    EXPECT_NEAR(estimate.translation().x(), 1.1 * k, 0.02) << "frame " << k;
    EXPECT_NEAR(estimate.translation().y(), 0.0, 0.05) << "frame " << k;
    EXPECT_NEAR(estimate.translation().z(), 0.0, 0.03) << "frame " << k;
  }
}

TEST(PosePrior, AScanWithoutReturnsTakesTheMeasuredMotion) {
  const auto boxes = msf::test::streetOfBoxes();
  msf::LidarOdometry odometry(snapshots());
  odometry.registerPoints(scanBoxes(boxes, sensorPose(0.0), 1));
  const Eigen::Isometry3d measured = sensorPose(1.3, 0.1, 0.01);
  const Eigen::Isometry3d pose = odometry.registerPoints({}, "scan 'empty'", &measured);
  EXPECT_TRUE(pose.isApprox(measured, 1e-6));
  EXPECT_EQ(odometry.poses().size(), 2u);
  // Without a measured motion an empty scan stays an error.
  EXPECT_THROW(odometry.registerPoints({}, "scan 'empty'"), msf::InvalidInputError);
}

} // namespace
