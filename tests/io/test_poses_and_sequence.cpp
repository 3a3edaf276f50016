// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>

#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <vector>

namespace fs = std::filesystem;

namespace {

using msf::test::errorOf;

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
  EXPECT_TRUE(seq.calibration().lidar.sweeping); // KITTI's Velodyne spins
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
  EXPECT_TRUE(seq.calibration().lidar.sweeping);
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

/// A copy of odometry 04 (links) with the frames `numbers` only, its times.txt and its poses.
std::string odometryWithFrames(const msf::test::TempDir& dir, const std::vector<int>& numbers) {
  const fs::path from = odometrySequence();
  const fs::path seq = fs::path(dir.path()) / "sequences" / "04";
  for (const char* sub : {"image_0", "image_1", "image_2", "velodyne"})
    fs::create_directories(seq / sub);
  fs::create_directories(fs::path(dir.path()) / "poses");
  fs::create_symlink(from / "calib.txt", seq / "calib.txt");
  fs::create_symlink(from / "times.txt", seq / "times.txt");
  fs::create_symlink(from.parent_path().parent_path() / "poses" / "04.txt", fs::path(dir.path()) / "poses" / "04.txt");
  char name[16];
  for (const int i : numbers) {
    for (const char* cam : {"image_0", "image_1", "image_2"}) {
      std::snprintf(name, sizeof name, "%06d.png", i);
      fs::create_symlink(from / cam / name, seq / cam / name);
    }
    std::snprintf(name, sizeof name, "%06d.bin", i);
    fs::create_symlink(from / "velodyne" / name, seq / "velodyne" / name);
  }
  return seq.string();
}

TEST(Sequence, FramesAreMatchedToPosesAndTimesByTheirNumberAcrossAGap) {
  // Frames 0, 1, 3, 4 (2 is missing): frame 3 has line 3's pose and time, not line 2's (which
  // is 1.3 m back), and -frames counts by the files' numbers.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Sequence full(odometrySequence());
  const msf::Sequence gap(odometryWithFrames(dir, {0, 1, 3, 4}));
  ASSERT_EQ(gap.size(), 4u);
  EXPECT_EQ(gap.frameName(2), "000003");
  EXPECT_TRUE(gap.poses()[2].isApprox(full.poses()[3]));
  EXPECT_TRUE(gap.poses()[3].isApprox(full.poses()[4]));
  const msf::Frame f = gap.load(2, false);
  EXPECT_TRUE(f.T_world_cam0.isApprox(full.poses()[3]));
  EXPECT_DOUBLE_EQ(f.timestamp, full.load(3, false).timestamp);
  const auto picked = gap.indices(msf::FrameRange::parse("2:4"));
  EXPECT_EQ(picked, (std::vector<std::size_t>{2, 3}));
  EXPECT_NE(errorOf([&] { gap.indices(msf::FrameRange::parse("2:2")); }).find("selects no frame"), std::string::npos);
  EXPECT_NE(errorOf([&] { gap.indices(msf::FrameRange::parse("0:5")); }).find("goes beyond the last frame"),
            std::string::npos);
}

TEST(Sequence, AFrameBeyondThePosesIsNamed) {
  // Frame 12 of a sequence whose poses have 10 lines: an error naming the frame, not the pose
  // of the line before.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string seq = odometryWithFrames(dir, {0, 1});
  for (const char* cam : {"image_0", "image_1"})
    fs::create_symlink(odometrySequence() + "/" + cam + "/000002.png", fs::path(seq) / cam / "000012.png");
  const std::string e = errorOf([&] { msf::Sequence s(seq); });
  EXPECT_NE(e.find("frame 000012 has no entry in poses '"), std::string::npos) << e;
  EXPECT_NE(e.find("04.txt', which has 10 (frames 0..9)"), std::string::npos) << e;
}

TEST(Sequence, TimesThatDoNotIncreaseAreNamed) {
  // A time that goes back or repeats would match two frames to one TUM pose and write a
  // poses_tum.txt going backwards.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string seq = odometryWithFrames(dir, {0, 1, 2});
  const fs::path times = fs::path(seq) / "times.txt";
  for (const std::string third : {"0.05", "0.1"}) {
    fs::remove(times);
    std::ofstream(times) << "0.0\n0.1\n" << third << "\n";
    EXPECT_EQ(errorOf([&] { msf::Sequence s(seq); }),
              "timestamps '" + times.string() + "' line 3 '" + third +
                  "' does not follow line 2's: the times must increase");
  }
  fs::remove(times);
  std::ofstream(times) << "0.0\n0.1\n0.2\n";
  EXPECT_EQ(msf::Sequence(seq).size(), 3u);
}

TEST(Sequence, StrayFilesBesideTheFramesAreNotFrames) {
  // macOS and editors leave files in image folders: .DS_Store (first by name: the image size
  // was read from it), a resource fork ._000000.png, a README, a copy.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string seq = odometryWithFrames(dir, {0, 1, 2});
  for (const char* stray : {"image_0/.DS_Store", "image_0/._000000.png", "image_0/README", "image_0/000001 (copy).png",
                            "velodyne/.DS_Store", "image_1/notes.txt"})
    std::ofstream(fs::path(seq) / stray) << "not an image";
  const msf::Sequence s(seq);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s.frameName(0), "000000");
  EXPECT_EQ(s.calibration().image_size, cv::Size(1226, 370));
  EXPECT_EQ(s.load(2, false).left.size(), cv::Size(1226, 370));
}

TEST(Sequence, ARawDriveMatchesOxtsRecordsByTheFramesName) {
  // A raw drive whose frame 2 is missing: frame 3 has OXTS record 3's pose (the record before
  // was kept before); a record missing for a frame is named.
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Sequence full(rawDrive());
  const fs::path date = fs::path(dir.path()) / "2011_09_26";
  const fs::path drive = date / "2011_09_26_drive_0009_sync";
  for (const char* f : {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt", "calib_imu_to_velo.txt"}) {
    fs::create_directories(date);
    fs::create_symlink(fs::path(rawDrive()).parent_path() / f, date / f);
  }
  for (const char* sub : {"image_00", "image_01"}) {
    fs::create_directories(drive / sub / "data");
    fs::create_symlink(fs::path(rawDrive()) / sub / "timestamps.txt", drive / sub / "timestamps.txt");
  }
  fs::create_directories(drive / "velodyne_points" / "data");
  fs::create_directories(drive / "oxts" / "data");
  char name[16];
  for (const int i : {0, 1, 3, 4}) {
    std::snprintf(name, sizeof name, "%010d", i);
    for (const char* sub : {"image_00", "image_01"})
      fs::create_symlink(fs::path(rawDrive()) / sub / "data" / (std::string(name) + ".png"),
                         drive / sub / "data" / (std::string(name) + ".png"));
    fs::create_symlink(fs::path(rawDrive()) / "velodyne_points" / "data" / (std::string(name) + ".bin"),
                       drive / "velodyne_points" / "data" / (std::string(name) + ".bin"));
    if (i != 4)
      fs::create_symlink(fs::path(rawDrive()) / "oxts" / "data" / (std::string(name) + ".txt"),
                         drive / "oxts" / "data" / (std::string(name) + ".txt"));
  }
  const std::string e = errorOf([&] { msf::Sequence s(drive.string()); });
  EXPECT_NE(e.find("frame 0000000004 has no OXTS record: '"), std::string::npos) << e;
  fs::create_symlink(fs::path(rawDrive()) / "oxts" / "data" / "0000000004.txt", drive / "oxts" / "data" / "0000000004.txt");
  const msf::Sequence gap(drive.string());
  ASSERT_EQ(gap.size(), 4u);
  EXPECT_TRUE(gap.poses()[2].isApprox(full.poses()[3], 1e-9));
  EXPECT_NEAR(gap.load(2, false).timestamp, full.load(3, false).timestamp, 1e-9);
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
