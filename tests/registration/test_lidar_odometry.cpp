// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "box_scene.h"
#include "test_support.h"

#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/registration/scan_constraints.h>
#include <msf/registration/scan_to_map_icp.h>
#include <msf/registration/sweep_deskew.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/evaluation/odometry_metrics.h>
#include <msf/synthetic/synthetic_generator.h>

#include <gtest/gtest.h>
#include <pcl/point_types.h>

#include <cmath>
#include <sstream>

namespace {

using msf::test::scanBoxes;
using msf::test::sensorPose;

double angleDeg(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.linear()).angle() * 180.0 / M_PI; }

/// The box scans are snapshots unless a test says otherwise.
msf::LidarOdometry::Config snapshots() {
  msf::LidarOdometry::Config config;
  config.deskew = "none";
  return config;
}

using msf::test::errorOf;

/// Scans of the synthetic street by its own LiDAR (msf_synth's scene and sensor; scans only,
/// no images): the geometry the odometry is measured on, built once for the suite.
template <typename Base>
class StreetFixture : public Base {
protected:
  static void SetUpTestSuite() {
    msf::synthetic::SyntheticConfig config;
    config.frames = 30;
    street_ = new msf::synthetic::SyntheticGenerator(config);
  }
  static void TearDownTestSuite() {
    delete street_;
    street_ = nullptr;
  }
  /// The LiDAR's pose at frame i of the street's drive.
  static Eigen::Isometry3d lidarPose(std::size_t i) { return street_->poses()[i] * street_->calibration().T_cam0_velo; }
  /// A scan from any pose, of the street at frame i's time (its moving cars where they are then).
  static msf::PointList scan(const Eigen::Isometry3d& T_world_velo, std::size_t time_frame, std::uint64_t key) {
    msf::PointList points;
    for (const auto& p : street_->lidar().scan(street_->sceneAt(time_frame), T_world_velo, key))
      points.emplace_back(p.x, p.y, p.z);
    return points;
  }
  inline static msf::synthetic::SyntheticGenerator* street_ = nullptr;
};
class StreetScans : public StreetFixture<::testing::TestWithParam<bool>> {}; // point_to_plane
class StreetDrive : public StreetFixture<::testing::Test> {};

/// The sensor moved by `forward` and `left` metres and turned by `yaw_deg`, in its own frame.
Eigen::Isometry3d move(double forward, double left, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << forward, left, 0.0;
  return T;
}

TEST_P(StreetScans, RecoversAKnownRigidMotionBetweenTwoScans) {
  // The same instant of the street (a rigid motion of the sensor only), two poses apart.
  const Eigen::Isometry3d T_w_a = lidarPose(5), truth = move(1.2, 0.15, 2.0), T_w_b = T_w_a * truth;
  const msf::PointList a = scan(T_w_a, 5, 1), b = scan(T_w_b, 5, 2); // independent noise
  std::vector<msf::PointMoments> moments;
  const msf::PointList frame = msf::voxelDownsample(a, 0.5, &moments);
  msf::LocalMap map(1.0, 10);
  map.addScan(frame, moments); // a's frame is the map's world
  msf::IcpSettings settings;
  settings.point_to_plane = GetParam();
  settings.max_correspondence_m = 1.0;
  settings.kernel_scale_m = 1.0 / 3.0;
  // From a prediction 0.25 m and half a degree off, as a constant-velocity one can be.
  const msf::IcpResult result =
      msf::alignScanToMap(msf::voxelDownsample(b, 1.5), map, truth * move(0.2, -0.15, 0.5), settings);
  const Eigen::Isometry3d error = truth.inverse() * result.T_world_sensor;
  EXPECT_LT(error.translation().norm(), 0.03) << error.translation().transpose();
  EXPECT_LT(angleDeg(error), 0.05);
  EXPECT_TRUE(result.converged);
  EXPECT_GT(result.correspondences, 500u);
  EXPECT_EQ(result.planes > 0, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Residual, StreetScans, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "PointToPlane" : "PointToPoint"; });

/// Straight down the street (world z) at 1.1 m a frame, at the height and heading of frame 0.
Eigen::Isometry3d straightAhead(const Eigen::Isometry3d& start, int k) {
  Eigen::Isometry3d T = start;
  T.translation() += Eigen::Vector3d(0, 0, 1.1 * k);
  return T;
}

TEST_F(StreetDrive, AStraightDriveAccumulatesNoRotation) {
  // At the street's instant of frame 0 (nothing moves), from a standing start of unknown motion.
  msf::LidarOdometry odometry(snapshots());
  const int frames = 20;
  for (int k = 0; k < frames; ++k)
    odometry.registerPoints(scan(straightAhead(lidarPose(0), k), 0, 100 + k));
  for (int k = 0; k < frames; ++k) {
    const Eigen::Isometry3d truth = lidarPose(0).inverse() * straightAhead(lidarPose(0), k);
    const Eigen::Isometry3d error = truth.inverse() * odometry.poses()[static_cast<std::size_t>(k)];
    EXPECT_LT(angleDeg(error), 0.2) << "frame " << k;
    EXPECT_LT(error.translation().norm(), 0.1) << "frame " << k;
  }
  const Eigen::Isometry3d last = odometry.poses().back();
  EXPECT_LT(angleDeg(last), 0.15); // 20.9 m, no turn
}

TEST_F(StreetDrive, PointToPointPairsHoldTheFirstRegistrationAtNoMotion) {
  // Why the first registration uses planes only: with one scan in the map, KISS-ICP's
  // point-to-point pairs on its rings register a 1.1 m move as a fraction of it.
  const msf::PointList first = scan(lidarPose(0), 0, 1), second = scan(straightAhead(lidarPose(0), 1), 0, 2);
  double moved[2];
  for (const bool planes : {false, true}) {
    msf::LidarOdometry::Config config = snapshots();
    config.point_to_plane = planes;
    msf::LidarOdometry odometry(config);
    odometry.registerPoints(first);
    moved[planes] = odometry.registerPoints(second).translation().norm();
  }
  EXPECT_NEAR(moved[true], 1.1, 0.03);
  EXPECT_LT(moved[false], 0.6);
}

TEST_F(StreetDrive, FollowsASlalom) {
  // 1.2 m a frame, swinging 1.5 m sideways and yawing by up to 3 degrees back and forth every
  // 13 frames: the constant-velocity prediction misses by decimetres and a degree or more.
  msf::LidarOdometry odometry(snapshots());
  for (int k = 0; k < 12; ++k) {
    const Eigen::Isometry3d truth = move(1.2 * k, 1.5 * std::sin(0.25 * k), 3.0 * std::sin(0.5 * k));
    const Eigen::Isometry3d error = truth.inverse() * odometry.registerPoints(scan(lidarPose(0) * truth, 0, 300 + k));
    EXPECT_LT(error.translation().norm(), 0.2) << "frame " << k;
    EXPECT_LT(angleDeg(error), 0.5) << "frame " << k;
  }
}

TEST(StreetOdometry, DrivesTheStreetWithItsMovingCars) {
  // The street's own drive, 30 frames at 10 m/s, a car ahead at our speed and oncoming ones:
  // the defaults (deskew resolves to none on the synthetic street's snapshots).
  msf::synthetic::SyntheticConfig config;
  config.frames = 30;
  const msf::synthetic::SyntheticGenerator street(config);
  const Eigen::Isometry3d T_cam0_velo = street.calibration().T_cam0_velo;
  msf::LidarOdometry odometry(snapshots());
  msf::PoseList estimate;
  for (std::size_t i = 0; i < street.size(); ++i)
    estimate.push_back(msf::cameraPose(
        odometry.registerScan(street.lidar().scan(street.sceneAt(i), street.poses()[i] * T_cam0_velo, i)), T_cam0_velo,
        street.poses().front()));
  const msf::OdometryMetrics m = msf::evaluateOdometry(estimate, street.poses());
  EXPECT_LT(m.end_drift_pct, 0.5);
  EXPECT_LT(m.ate_rmse_m, 0.05);
}

TEST(LidarOdometry, DegenerateScansAreErrorsThatNameTheScanNotAPose) {
  msf::LidarOdometry odometry(snapshots());
  // Empty, and all NaN.
  EXPECT_NE(errorOf([&] { odometry.registerPoints({}, "scan 'empty.bin'"); }).find("scan 'empty.bin': no points"),
            std::string::npos);
  pcl::PointCloud<pcl::PointXYZI> nans;
  nans.resize(50);
  for (auto& p : nans)
    p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  const std::string nan_message = errorOf([&] { odometry.registerScan(nans, "scan 'nan.bin'"); });
  EXPECT_NE(nan_message.find("scan 'nan.bin': none of its 50 points is a finite return"), std::string::npos)
      << nan_message;
  // A single plane: the road alone constrains height, roll and pitch only.
  const std::vector<msf::test::Box> road{{{-100, -100, -1}, {100, 100, 0}}};
  const msf::PointList plane = scanBoxes(road, sensorPose(0.0), 5);
  ASSERT_GT(plane.size(), 5000u);
  const std::string plane_message = errorOf([&] { odometry.registerPoints(plane, "scan 'road.bin'"); });
  EXPECT_NE(plane_message.find("scan 'road.bin': its planes leave 3 of 6 degrees of freedom unconstrained"),
            std::string::npos)
      << plane_message;
  EXPECT_TRUE(odometry.poses().empty());
  EXPECT_TRUE(odometry.map().empty());

  // After a good first scan, a degenerate one leaves the odometry as it was.
  const auto boxes = msf::test::streetOfBoxes();
  odometry.registerPoints(scanBoxes(boxes, sensorPose(0.0), 6));
  const std::size_t map_size = odometry.map().size();
  EXPECT_THROW(odometry.registerPoints(scanBoxes(road, sensorPose(1.0), 7)), msf::InvalidInputError);
  EXPECT_EQ(odometry.poses().size(), 1u);
  EXPECT_EQ(odometry.map().size(), map_size);
  // A good scan out of the map's reach (30 m above it): no pair, an error, not the prediction.
  msf::PointList lifted = scanBoxes(boxes, sensorPose(0.0), 8);
  for (auto& p : lifted)
    p.z() += 30.0;
  const std::string far = errorOf([&] { odometry.registerPoints(lifted, "scan 'far'"); });
  EXPECT_NE(far.find("scan 'far': scan-to-map ICP"), std::string::npos) << far;
}

TEST(SweepDeskew, MovesEachPointByItsShareOfTheTurn) {
  // 1.2 m forward and 2 degrees to the left in a turn; the point ahead was seen mid-turn.
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  motion.translation() << 1.2, 0.0, 0.0;
  const msf::PointList points{{10, 0, 0}, {0, 10, 0}, {0, -10, 0}, {-10, 1e-9, 0}};
  const msf::PointList out = msf::deskewSweep(points, motion);
  EXPECT_TRUE(out[0].isApprox(points[0]));
  // A quarter turn later on the left: a quarter of the motion.
  const double yaw = 0.25 * 2.0 * M_PI / 180.0;
  EXPECT_NEAR(out[1].x(), 0.25 * 1.2 - 10.0 * yaw, 1e-9);
  EXPECT_NEAR(out[2].x(), -0.25 * 1.2 - 10.0 * yaw, 1e-9);
  EXPECT_NEAR(out[3].x(), -10.0 + 0.5 * 1.2, 1e-6); // behind: the end of the turn
}

TEST(SweepDeskew, TimesEachPointByItsAzimuthAllRoundTheTurn) {
  // Points all round at 50 m, under a fast motion: each must move by atan2's share of it.
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.1, 0.2, 1.0).normalized()).toRotationMatrix();
  motion.translation() << 2.0, -0.5, 0.1;
  const Eigen::AngleAxisd rotation(motion.linear());
  const Eigen::Vector3d omega = rotation.angle() * rotation.axis();
  msf::PointList points;
  for (int k = -3600; k < 3600; ++k) { // 0.05 degree apart, past every octant's edge
    const double a = k * M_PI / 3600.0 + 1e-4;
    points.emplace_back(50.0 * std::cos(a), 50.0 * std::sin(a), 0.1 * (k % 7));
  }
  points.emplace_back(0.0, 0.0, 5.0); // straight up: no azimuth, no move
  points.emplace_back(-50.0, 0.0, 0.0); // straight behind: half a turn
  const msf::PointList out = msf::deskewSweep(points, motion);
  ASSERT_EQ(out.size(), points.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double s = std::atan2(p.y(), p.x()) / (2.0 * M_PI);
    worst = std::max(worst, (out[i] - (p + s * (omega.cross(p) + motion.translation()))).norm());
  }
  EXPECT_LT(worst, 1e-7); // metres
}

TEST(ScanConstraints, CountsTheDirectionsAScanPinsDown) {
  const std::vector<msf::test::Box> road{{{-100, -100, -1}, {100, 100, 0}}};
  const auto plane = msf::analyzeConstraints(msf::voxelDownsample(scanBoxes(road, sensorPose(0.0), 1), 0.5), 2.0);
  EXPECT_EQ(plane.unconstrained(1e-3), 3);
  EXPECT_GT(plane.patches, 50u);
  // A corridor: the road and two walls leave the travel direction free.
  const std::vector<msf::test::Box> corridor{
      {{-300, -100, -1}, {300, 100, 0}}, {{-300, -10, 0}, {300, -9, 6}}, {{-300, 9, 0}, {300, 10, 6}}};
  const auto tunnel = msf::analyzeConstraints(msf::voxelDownsample(scanBoxes(corridor, sensorPose(0.0), 2), 0.5), 2.0);
  EXPECT_EQ(tunnel.unconstrained(1e-3), 1);
  EXPECT_NE(tunnel.weakestDirection().find("translation along (1.00, 0.00, 0.00)"), std::string::npos)
      << tunnel.weakestDirection();
  const auto street =
      msf::analyzeConstraints(msf::voxelDownsample(scanBoxes(msf::test::streetOfBoxes(), sensorPose(0.0), 3), 0.5), 2.0);
  EXPECT_EQ(street.unconstrained(1e-3), 0);
  EXPECT_EQ(msf::analyzeConstraints({}, 2.0).unconstrained(1e-3), 6);
}

TEST(LidarOdometry, CameraPoseGoesThroughTheCalibration) {
  // KITTI's axes: the LiDAR's x forward, y left, z up; the camera's z forward, x right, y down.
  Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity();
  T_cam0_velo.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  T_cam0_velo.translation() << 0.0, -0.08, -0.27;
  Eigen::Isometry3d forward = Eigen::Isometry3d::Identity();
  forward.translation() << 2.0, 0.0, 0.0;
  const Eigen::Isometry3d T = msf::cameraPose(forward, T_cam0_velo);
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0, 0, 2), 1e-12));
  EXPECT_TRUE(T.linear().isIdentity(1e-12));
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.translation() << 5, 0, 0;
  EXPECT_TRUE(msf::cameraPose(Eigen::Isometry3d::Identity(), T_cam0_velo, start).isApprox(start));
}

TEST(LidarOdometryConfig, ReadsPrintsAndRejectsBadValues) {
  msf::LidarOdometry::Config config;
  config.voxel_size_m = 0.75;
  config.point_to_plane = false;
  config.min_constraint = 0.004;
  std::ostringstream printed;
  msf::printConfig(printed, config);
  msf::LidarOdometry::Config again;
  msf::ConfigFile::fromText(printed.str(), "odometry.yaml").read(again);
  std::ostringstream printed_again;
  msf::printConfig(printed_again, again);
  EXPECT_EQ(printed_again.str(), printed.str());
  EXPECT_EQ(again.voxel_size_m, 0.75);
  EXPECT_FALSE(again.point_to_plane);

  auto rejected = [](const std::function<void(msf::LidarOdometry::Config&)>& edit, const std::string& key) {
    msf::LidarOdometry::Config c;
    edit(c);
    try {
      c.validate();
    } catch (const msf::ConfigError& e) {
      return std::string(e.what()).find("odometry." + key) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(rejected([](auto& c) { c.voxel_size_m = 0; }, "voxel_size_m"));
  EXPECT_TRUE(rejected([](auto& c) { c.min_range_m = 200; }, "min_range_m"));
  EXPECT_TRUE(rejected([](auto& c) { c.max_points_per_voxel = 0; }, "max_points_per_voxel"));
  EXPECT_TRUE(rejected([](auto& c) { c.max_iterations = 0; }, "max_iterations"));
  EXPECT_TRUE(rejected([](auto& c) { c.min_constraint = 1.0; }, "min_constraint"));
  EXPECT_TRUE(rejected([](auto& c) { c.deskew = "yes"; }, "deskew"));
  EXPECT_THROW(msf::LidarOdometry(msf::LidarOdometry::Config{0.0}), msf::ConfigError);
}

} // namespace
