// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The rig file: a user's own sensors in plain YAML, read back exactly, each key refused by name
// when it is missing, misspelt or cannot be right.
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/rig_file.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace {

const char* const kRig = R"(# a 640x480 pair, 12 cm apart, and a 32-beam LiDAR 20 cm above the left camera
image_width: 640
image_height: 480
left: {fx: 500.0, fy: 501.0, cx: 320.5, cy: 240.25}
baseline_m: 0.12
lidar:
  T_cam_lidar: [0, -1, 0, 0,
                0, 0, -1, -0.2,
                1, 0, 0, 0,
                0, 0, 0, 1]
  rings: 4
  beam_elevations_deg: [-15, -5, 5, 15]
  sweeping: false
)";

std::string write(const msf::test::TempDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir.file(name)) << text;
  return dir.file(name);
}

/// The rig above with `from` replaced by `to` (once).
std::string edited(const std::string& from, const std::string& to) {
  std::string text = kRig;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

} // namespace

TEST(RigFile, ReadsTheCamerasTheBaselineAndTheLidar) {
  msf::test::TempDir dir;
  const msf::Calibration c = msf::loadCalibration(write(dir, "rig.yaml", kRig)); // detected as a rig file
  EXPECT_EQ(c.image_size, cv::Size(640, 480));
  EXPECT_DOUBLE_EQ(c.fx(), 500.0);
  EXPECT_DOUBLE_EQ(c.fy(), 501.0);
  EXPECT_DOUBLE_EQ(c.cx(), 320.5);
  EXPECT_DOUBLE_EQ(c.cy(), 240.25);
  EXPECT_NEAR(c.baselineGrey(), 0.12, 1e-12);
  EXPECT_NEAR(c.focalBaseline(), 60.0, 1e-9);
  EXPECT_TRUE(c.P[2].isApprox(c.P[0])); // no colour camera: the left one colours
  ASSERT_TRUE(c.has_velodyne);
  // A point 10 m ahead of the LiDAR (its x) is 10 m ahead of the camera (its z), 0.2 m up.
  const Eigen::Vector3d p = c.T_cam0_velo * Eigen::Vector3d(10, 0, 0);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(0, -0.2, 10))) << p.transpose();
  EXPECT_EQ(c.lidar.rings, 4);
  EXPECT_EQ(c.lidar.beam_elevations_deg, (std::vector<double>{-15, -5, 5, 15}));
  EXPECT_FALSE(c.lidar.sweeping);
}

TEST(RigFile, ARigMadeInCodeIsTheRigItsFileGives) {
  msf::test::TempDir dir;
  const msf::Calibration file = msf::loadRigFile(write(dir, "rig.yaml", kRig));
  msf::Calibration::Lidar lidar;
  lidar.beam_elevations_deg = {-15, -5, 5, 15};
  lidar.sweeping = false;
  const Eigen::Isometry3d T = file.T_cam0_velo;
  const msf::Calibration code = msf::makeRig({640, 480}, 500.0, 501.0, 320.5, 240.25, 0.12, &T, lidar);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(code.P[i], file.P[i]) << "P" << i;
  EXPECT_EQ(code.T_cam0_velo.matrix(), file.T_cam0_velo.matrix());
  EXPECT_EQ(code.lidar.rings, 4);
  EXPECT_FALSE(code.lidar.sweeping);
  EXPECT_FALSE(msf::makeRig({640, 480}, 500.0, 500.0, 320.0, 240.0, 0.12, nullptr).has_velodyne);
  EXPECT_NE(msf::test::errorOf([] { msf::makeRig({640, 480}, 500.0, 500.0, 320.0, 240.0, 0.0, nullptr); })
                .find("the baseline must be > 0"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([] { msf::makeRig({0, 0}, 500.0, 500.0, 320.0, 240.0, 0.12, nullptr); })
                .find("the image size must be given"),
            std::string::npos);
}

TEST(RigFile, AFileWithOpenCvsFirstLineReads) {
  msf::test::TempDir dir;
  const msf::Calibration c = msf::loadCalibration(write(dir, "rig.yaml", std::string("%YAML:1.0\n") + kRig));
  EXPECT_EQ(c.image_size, cv::Size(640, 480));
  EXPECT_EQ(c.lidar.rings, 4);
}

TEST(RigFile, WrittenAndReadBackIsTheSameCalibration) {
  msf::test::TempDir dir;
  const msf::Calibration c = msf::loadRigFile(write(dir, "rig.yaml", kRig));
  msf::saveRigFile(c, dir.file("again.yaml"));
  const msf::Calibration again = msf::loadRigFile(dir.file("again.yaml"));
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(again.P[i], c.P[i]) << "P" << i; // exact: written with every digit a double has
  EXPECT_EQ(again.T_cam0_velo.matrix(), c.T_cam0_velo.matrix());
  EXPECT_EQ(again.image_size, c.image_size);
  EXPECT_EQ(again.lidar.beam_elevations_deg, c.lidar.beam_elevations_deg);
  EXPECT_EQ(again.lidar.sweeping, c.lidar.sweeping);
  // PyYAML reads it: the rig is plain YAML for the user's own scripts.
  const auto r = msf::test::runCommand("python3 -c \"import yaml; r = yaml.safe_load(open('" + dir.file("again.yaml") +
                                       "')); print(r['image_width'], len(r['right']['P']), r['lidar']['rings'])\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "640 12 4\n");
}

TEST(RigFile, EachFaultIsRefusedNamingTheKey) {
  msf::test::TempDir dir;
  const struct {
    std::string text, message;
  } cases[] = {
      {edited("image_width: 640\n", ""), "image_width is missing"},
      {edited("image_height: 480", "image_height: 48.5"), "image_height must be a whole number"},
      {edited("fx: 500.0", "fx: -500.0"), "left needs focal lengths > 0"},
      {edited("cy: 240.25", "cy: abc"), "left.cy must be a number, not 'abc'"},
      {edited("baseline_m: 0.12", "baseline_m: -0.12"), "are the cameras swapped?"},
      {edited("baseline_m: 0.12\n", ""), "baseline_m (or right) is missing"},
      {edited("baseline_m: 0.12", "baseline_m: 0.12\nright: {P: [500, 0, 320, -60, 0, 500, 240, 0, 0, 0, 1, 0]}"),
       "baseline_m and right are both given"},
      {edited("0, 0, -1, -0.2,", "0, 0, -2, -0.2,"), "lidar.T_cam_lidar must be a rigid transform"},
      {edited("0, 0, 0, 1]", "0, 0, 0]"), "lidar.T_cam_lidar must hold 16 numbers, not 15"},
      {edited("rings: 4", "rings: 32"), "lidar.beam_elevations_deg must hold one elevation per ring (32), not 4"},
      {edited("[-15, -5, 5, 15]", "[-15, 5, -5, 15]"), "lidar.beam_elevations_deg must rise"},
      {edited("sweeping: false", "sweeping: maybe"), "lidar.sweeping must be true or false"},
      {edited("left: {fx: 500.0, fy: 501.0, cx: 320.5, cy: 240.25}",
              "left: {P: [500, 0, 320, 7, 0, 500, 240, 0, 0, 0, 1, 0]}"),
       "left.P must have no translation column"},
      // yaml-cpp keeps both and a lookup sees the first: refused, as in a config file.
      {edited("baseline_m: 0.12", "baseline_m: 0.12\nbaseline_m: 0.5"),
       "baseline_m appears twice (lines 5 and 6)"},
      {edited("  rings: 4", "  rings: 4\n  rings: 8"), "lidar.rings appears twice (lines 11 and 12)"},
      // Misspelt: each would leave its value at the default (a 16-beam LiDAR read as KITTI's).
      {edited("baseline_m: 0.12", "baseline_m: 0.12\ncolour: {fx: 1, fy: 1, cx: 0, cy: 0}"),
       "line 6: 'colour' is not a key of a rig file (image_width, image_height, left, right, baseline_m, color, "
       "color_right, lidar)"},
      {edited("beam_elevations_deg:", "beam_elevation_deg:"),
       "line 12: 'beam_elevation_deg' is not a key of lidar (T_cam_lidar, rings, beam_elevations_deg, sweeping)"},
      {edited("sweeping: false", "sweep: false"), "'sweep' is not a key of lidar"},
      {edited("cy: 240.25", "cy: 240.25, k1: 0.1"), "'k1' is not a key of left (fx, fy, cx, cy, P)"},
      // Still a rig file without its first keys: the missing one is named, not "not valid YAML".
      {edited("left: {fx: 500.0, fy: 501.0, cx: 320.5, cy: 240.25}\n", ""), "left is missing"},
      {edited("image_width: 640\nimage_height: 480\n", ""), "image_width is missing"},
      // Every key misspelt is still a rig file (OpenCV's files start with %YAML), its first key named.
      {"imagewidth: 640\nleftcam: {fx: 500, fy: 500, cx: 320, cy: 240}\n",
       "line 1: 'imagewidth' is not a key of a rig file"},
  };
  for (const auto& c : cases) {
    const std::string path = write(dir, "bad.yaml", c.text);
    const std::string error = msf::test::errorOf([&] { msf::loadCalibration(path); }); // as the tools read it
    EXPECT_NE(error.find(c.message), std::string::npos) << "expected: " << c.message << "\ngot: " << error;
    EXPECT_NE(error.find(path), std::string::npos) << error;
  }
  const std::string deep = write(dir, "deep.yaml", "image_width: " + std::string(5000, '[') + std::string(5000, ']'));
  EXPECT_NE(msf::test::errorOf([&] { msf::loadRigFile(deep); }).find("levels deep (yaml-cpp's limit)"),
            std::string::npos);
  const std::string not_yaml = write(dir, "broken.yaml", "image_width: [640\nleft: {fx");
  EXPECT_NE(msf::test::errorOf([&] { msf::loadRigFile(not_yaml); }).find("is not valid YAML"), std::string::npos);
}
