#include <msf/common/exceptions.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>

#include "test_support.h"

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

std::string odometrySequence() { return msf::test::kittiDir() + "/odometry/sequences/04"; }
std::string rawDrive() { return msf::test::kittiDir() + "/raw/2011_09_26/2011_09_26_drive_0009_sync"; }

TEST(Poses, OdometryPosesOfSequence04) {
  MSF_REQUIRE_KITTI();
  const auto poses = msf::loadOdometryPoses(msf::test::kittiDir() + "/odometry/poses/04.txt");
  ASSERT_EQ(poses.size(), 10u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity(), 1e-6));
  // Frame 9 is 11.9 m ahead along camera 0's optical axis, 0.94 s later (~45 km/h).
  EXPECT_NEAR(poses[9].translation().z(), 11.90426, 1e-5);
  EXPECT_TRUE(poses[9].linear().isUnitary(1e-5));
}

TEST(Poses, RoundTripAndMalformedLine) {
  msf::test::TempDir dir;
  msf::PoseList poses(3, Eigen::Isometry3d::Identity());
  poses[2].translation() << 1.5, -2.25, 30.125;
  poses[1].linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  msf::saveOdometryPoses(dir.file("p.txt"), poses);
  const auto back = msf::loadOdometryPoses(dir.file("p.txt"));
  ASSERT_EQ(back.size(), 3u);
  EXPECT_TRUE(back[1].isApprox(poses[1], 1e-8));
  EXPECT_TRUE(back[2].isApprox(poses[2], 1e-8));

  std::ofstream(dir.file("bad.txt")) << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n";
  try {
    msf::loadOdometryPoses(dir.file("bad.txt"));
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  // Twelve numbers that are no rigid motion (a scale, a mirror) are errors, not a trajectory.
  for (const char* matrix : {"2 0 0 0 0 2 0 0 0 0 2 0", "-1 0 0 0 0 1 0 0 0 0 1 0"}) {
    std::ofstream(dir.file("scaled.txt")) << "1 0 0 0 0 1 0 0 0 0 1 0\n" << matrix << "\n";
    try {
      msf::loadOdometryPoses(dir.file("scaled.txt"));
      FAIL() << "expected IOError for " << matrix;
    } catch (const msf::IOError& e) {
      EXPECT_NE(std::string(e.what()).find("line 2 is not a rigid transform"), std::string::npos) << e.what();
    }
  }
}

TEST(Poses, RawOxtsGiveCameraPosesFromTheFirstFrame) {
  MSF_REQUIRE_KITTI();
  const msf::Calibration calibration = msf::loadCalibration(msf::test::kittiDir() + "/raw/2011_09_26");
  const auto oxts = msf::loadOxts(rawDrive() + "/oxts/data");
  ASSERT_EQ(oxts.size(), 5u);
  EXPECT_NEAR(oxts[0].lat, 49.009347760599, 1e-9);
  const auto poses = msf::oxtsToCameraPoses(oxts, calibration);
  ASSERT_EQ(poses.size(), 5u);
  EXPECT_LT((poses[0].matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-6);
  // The car drives forward at 10.71 m/s (oxts vf) for 0.41998 s (oxts/timestamps.txt):
  // 4.50 m along camera 0's z, with little sideways (x) or vertical (y) motion.
  const Eigen::Vector3d t = poses[4].translation();
  EXPECT_NEAR(t.z(), 10.71 * 0.41998, 0.05);
  EXPECT_LT(std::abs(t.x()), 0.5);
  EXPECT_LT(std::abs(t.y()), 0.3);
}

TEST(Sequence, OdometryLayout) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence seq(odometrySequence());
  EXPECT_EQ(seq.layout(), msf::Sequence::Layout::Odometry);
  ASSERT_EQ(seq.size(), 10u);
  EXPECT_TRUE(seq.hasPoses());
  EXPECT_EQ(seq.frameName(3), "000003");
  const msf::Frame f = seq.load(3);
  EXPECT_GT(f.scan->size(), 100000u);
  EXPECT_EQ(f.left.size(), cv::Size(1226, 370));
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_EQ(f.right.type(), CV_8UC1);
  EXPECT_EQ(f.color.type(), CV_8UC3);
  EXPECT_NEAR(f.timestamp, 0.3123, 1e-3);
  EXPECT_TRUE(f.has_pose);
  EXPECT_TRUE(f.T_world_cam0.isApprox(seq.poses()[3]));
  EXPECT_EQ(seq.indices(msf::FrameRange::parse("2:4")).size(), 3u);
  EXPECT_EQ(seq.indices(msf::FrameRange::parse("7:")).size(), 3u);
  EXPECT_THROW(seq.indices(msf::FrameRange::parse("20:30")), msf::InvalidInputError);
  EXPECT_THROW(seq.load(10), msf::InvalidInputError);
}

TEST(Sequence, RawLayout) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence seq(rawDrive());
  EXPECT_EQ(seq.layout(), msf::Sequence::Layout::Raw);
  ASSERT_EQ(seq.size(), 5u);
  EXPECT_TRUE(seq.hasPoses());
  const msf::Frame f = seq.load(1, false);
  EXPECT_EQ(f.left.size(), cv::Size(1242, 375));
  EXPECT_TRUE(f.color.empty());
  EXPECT_NEAR(f.timestamp, 0.1038, 1e-3);
  EXPECT_GT(f.T_world_cam0.translation().z(), 0.5);
}

TEST(Sequence, MissingScanIsNamed) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const fs::path seq = fs::path(dir.path()) / "sequences" / "04";
  for (const char* sub : {"image_0", "image_1", "velodyne"})
    fs::create_directories(seq / sub);
  fs::copy_file(odometrySequence() + "/calib.txt", seq / "calib.txt");
  for (const char* cam : {"image_0", "image_1"})
    fs::create_symlink(odometrySequence() + "/" + cam + "/000000.png", seq / cam / "000000.png");
  // The dataset root is accepted when it holds one sequence.
  const msf::Sequence s(dir.path());
  ASSERT_EQ(s.size(), 1u);
  EXPECT_FALSE(s.hasPoses());
  try {
    s.load(0);
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("velodyne/000000.bin"), std::string::npos) << e.what();
  }
}

TEST(Sequence, FolderOfNeitherLayoutIsAnError) {
  msf::test::TempDir dir;
  try {
    msf::Sequence s(dir.path());
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("neither"), std::string::npos) << e.what();
  }
  EXPECT_THROW(msf::Sequence("/nonexistent/sequence"), msf::IOError);
}

TEST(FrameRange, Parsing) {
  EXPECT_EQ(msf::FrameRange::parse("0:9").last, 9);
  EXPECT_EQ(msf::FrameRange::parse("3:").last, -1);
  EXPECT_EQ(msf::FrameRange::parse(":4").first, 0);
  EXPECT_EQ(msf::FrameRange::parse("5").first, 5);
  EXPECT_THROW(msf::FrameRange::parse("9:3"), msf::InvalidInputError);
  EXPECT_THROW(msf::FrameRange::parse("a:b"), msf::InvalidInputError);
  EXPECT_THROW(msf::FrameRange::parse("-1:2"), msf::InvalidInputError);
}

} // namespace
