// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>
#include <msf/io/rig_file.h>
#include <msf/io/velodyne_io.h>

#include "test_support.h"

#include <fstream>
#include <limits>
#include <sstream>

namespace {

std::string odometryCalib() { return msf::test::kittiDir() + "/odometry/sequences/04/calib.txt"; }
std::string rawDateDir() { return msf::test::kittiDir() + "/raw/2011_09_26"; }

Eigen::Vector2d project(const msf::Calibration& c, const Eigen::Vector3d& p_velo) {
  const Eigen::Vector3d p_cam = c.T_cam0_velo * p_velo;
  const Eigen::Vector3d uvw = c.P[0] * p_cam.homogeneous();
  return uvw.head<2>() / uvw.z();
}

TEST(Calibration, OdometryCalibTxt) {
  MSF_REQUIRE_KITTI();
  const msf::Calibration c = msf::loadCalibration(odometryCalib());
  EXPECT_NEAR(c.fx(), 707.0912, 1e-4);
  EXPECT_NEAR(c.cy(), 183.1104, 1e-4);
  EXPECT_NEAR(c.baselineGrey(), 379.8145 / 707.0912, 1e-6);
  EXPECT_NEAR(c.baselineGrey(), 0.54, 0.01);
  EXPECT_NEAR(c.baselineColor(), 0.54, 0.01);
  EXPECT_EQ(c.image_size, cv::Size(1226, 370)); // read from image_0 beside calib.txt
  // Tr maps the velodyne's forward axis (x) onto the camera's optical axis (z).
  EXPECT_NEAR(c.T_cam0_velo.linear()(2, 0), 0.99998, 1e-4);
  EXPECT_NEAR(c.T_cam0_velo.translation().z(), -0.333997, 1e-5);
  EXPECT_TRUE(c.T_cam0_velo.linear().isUnitary(1e-5));
}

TEST(Calibration, ACameraIndexOutside0To3IsRefusedByEveryAccessor) {
  msf::Calibration c;
  for (auto& P : c.P)
    P << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  for (int camera : {-1, 4, 100000}) {
    const std::string message = "camera index " + std::to_string(camera) + " is not 0..3";
    EXPECT_THROW(c.K(camera), msf::InvalidInputError);
    EXPECT_EQ(msf::test::errorOf([&] { c.K(camera); }), message);
    EXPECT_EQ(msf::test::errorOf([&] { c.fx(camera); }), message);
    EXPECT_EQ(msf::test::errorOf([&] { c.cameraCenter(camera); }), message);
    EXPECT_EQ(msf::test::errorOf([&] { c.baseline(0, camera); }), message);
  }
  EXPECT_DOUBLE_EQ(c.K(3)(0, 0), 700.0);
}

TEST(PinholeCamera, IsValidOnlyWithFinitePositiveFocalLengthsAFinitePrincipalPointAndASize) {
  const msf::PinholeCamera good{500.f, 500.f, 320.f, 240.f, 640, 480};
  EXPECT_TRUE(good.valid());
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const msf::PinholeCamera& bad :
       {msf::PinholeCamera{0.f, 500.f, 320.f, 240.f, 640, 480}, msf::PinholeCamera{inf, 500.f, 320.f, 240.f, 640, 480},
        msf::PinholeCamera{500.f, nan, 320.f, 240.f, 640, 480}, msf::PinholeCamera{500.f, 500.f, nan, 240.f, 640, 480},
        msf::PinholeCamera{500.f, 500.f, 320.f, inf, 640, 480}, msf::PinholeCamera{500.f, 500.f, 320.f, 240.f, 0, 480}})
    EXPECT_FALSE(bad.valid()) << bad.fx << " " << bad.fy << " " << bad.cx << " " << bad.cy << " " << bad.width;
}

TEST(Calibration, AFolderHoldingCalibTxtIsTheSame) {
  MSF_REQUIRE_KITTI();
  const msf::Calibration a = msf::loadCalibration(odometryCalib());
  const msf::Calibration b = msf::loadCalibration(msf::test::kittiDir() + "/odometry/sequences/04");
  EXPECT_TRUE(a.P[1].isApprox(b.P[1]));
  EXPECT_TRUE(a.T_cam0_velo.isApprox(b.T_cam0_velo));
}

TEST(Calibration, RawDateFolder) {
  MSF_REQUIRE_KITTI();
  const msf::Calibration c = msf::loadCalibration(rawDateDir());
  EXPECT_NEAR(c.fx(), 721.5377, 1e-4);
  EXPECT_EQ(c.image_size, cv::Size(1242, 375));
  EXPECT_NEAR(c.baselineGrey(), 0.5372, 1e-3);
  EXPECT_NEAR(c.baselineColor(), 0.5327, 2e-3);
  EXPECT_TRUE(c.has_imu);
  EXPECT_NEAR(c.T_velo_imu.translation().x(), -0.8086759, 1e-7);
  // T_cam0_velo = R_rect_00 * [R|T] of calib_velo_to_cam.txt
  EXPECT_NEAR(c.T_cam0_velo.translation().y(), -0.0763, 3e-3);
  // The drive folder and calib_cam_to_cam.txt itself are accepted too.
  const msf::Calibration d = msf::loadCalibration(rawDateDir() + "/2011_09_26_drive_0009_sync");
  const msf::Calibration e = msf::loadCalibration(rawDateDir() + "/calib_cam_to_cam.txt");
  EXPECT_TRUE(c.T_cam0_velo.isApprox(d.T_cam0_velo));
  EXPECT_TRUE(c.P[3].isApprox(e.P[3]));
}

TEST(Calibration, RawAndOdometryProjectALidarPointIntoTheSameRegion) {
  MSF_REQUIRE_KITTI();
  const msf::Calibration odo = msf::loadCalibration(odometryCalib());
  const msf::Calibration raw = msf::loadCalibration(rawDateDir());
  // Both rigs carry the camera above and behind the LiDAR's origin, with nearly the same
  // intrinsics: a point 15 m ahead lands on nearby pixels in both.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(15, 0, -1), Eigen::Vector3d(15, 3, 0), Eigen::Vector3d(8, -2, -1.5)}) {
    const Eigen::Vector2d a = project(odo, p), b = project(raw, p);
    EXPECT_LT((a - b).norm(), 25.0) << p.transpose() << ": " << a.transpose() << " vs " << b.transpose();
    EXPECT_GT(a.x(), 0);
    EXPECT_LT(a.x(), 1226);
  }
  // And a real scan covers the image of each: ~15 % of a scan is in front of the camera.
  for (const auto& [calib, scan] :
       {std::pair{odo, msf::test::kittiDir() + "/odometry/sequences/04/velodyne/000000.bin"},
        std::pair{raw, rawDateDir() + "/2011_09_26_drive_0009_sync/velodyne_points/data/0000000000.bin"}}) {
    pcl::PointCloud<pcl::PointXYZI> cloud;
    msf::loadVelodyneBin(scan, cloud);
    std::size_t inside = 0;
    for (const auto& pt : cloud) {
      const Eigen::Vector3d pc = calib.T_cam0_velo * Eigen::Vector3d(pt.x, pt.y, pt.z);
      if (pc.z() < 0.5)
        continue;
      const Eigen::Vector3d uvw = calib.P[0] * pc.homogeneous();
      const double u = uvw.x() / uvw.z(), v = uvw.y() / uvw.z();
      inside += (u >= 0 && v >= 0 && u < calib.image_size.width && v < calib.image_size.height);
    }
    const double share = static_cast<double>(inside) / cloud.size();
    EXPECT_GT(share, 0.10) << scan;
    EXPECT_LT(share, 0.30) << scan;
  }
}

TEST(Calibration, YamlRoundTrip) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Calibration c = msf::loadCalibration(rawDateDir());
  msf::saveCalibrationYaml(c, dir.file("camera.yaml"));
  const msf::Calibration y = msf::loadCalibration(dir.file("camera.yaml"));
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(c.P[i].isApprox(y.P[i], 1e-12));
  EXPECT_TRUE(c.T_cam0_velo.isApprox(y.T_cam0_velo, 1e-12));
  EXPECT_EQ(y.image_size, c.image_size);
  EXPECT_TRUE(y.lidar.sweeping);
  EXPECT_TRUE(y.lidar.beam_elevations_deg.empty());
  // A rig's LiDAR description is kept: a snapshot LiDAR of three beams reads back as one.
  msf::Calibration rig = c;
  rig.lidar = {3, {-10.0, -4.0, 2.0}, false};
  msf::saveCalibrationYaml(rig, dir.file("rig.yaml"));
  const msf::Calibration r = msf::loadCalibration(dir.file("rig.yaml"));
  EXPECT_FALSE(r.lidar.sweeping);
  EXPECT_EQ(r.lidar.rings, 3);
  EXPECT_EQ(r.lidar.beam_elevations_deg, rig.lidar.beam_elevations_deg);
  // And as an odometry calib.txt.
  msf::saveOdometryCalibration(c, dir.file("calib.txt"));
  const msf::Calibration o = msf::loadCalibration(dir.file("calib.txt"));
  EXPECT_TRUE(c.P[2].isApprox(o.P[2], 1e-9));
  EXPECT_TRUE(c.T_cam0_velo.isApprox(o.T_cam0_velo, 1e-9));
}

TEST(Calibration, ValidateChecksTheLidarsBeams) {
  const Eigen::Isometry3d lidar = Eigen::Isometry3d::Identity();
  msf::Calibration c = msf::makeRig(cv::Size(64, 48), 50, 50, 32, 24, 0.5, &lidar, {3, {-10.0, -4.0, 2.0}, true});
  c.validate();
  c.lidar.rings = 32; // as a program may set it by hand
  EXPECT_NE(msf::test::errorOf([&] { c.validate(); })
                .find("lidar.rings is 32 but lidar.beam_elevations_deg holds 3: one elevation per ring"),
            std::string::npos);
  c.lidar.rings = 3;
  c.lidar.beam_elevations_deg = {-10.0, 2.0, -4.0};
  EXPECT_NE(msf::test::errorOf([&] { c.validate(); })
                .find("lidar.beam_elevations_deg must rise from the lowest beam to the highest"),
            std::string::npos);
}

class CalibrationErrors : public ::testing::Test {
protected:
  msf::test::TempDir dir;
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir.file(name)) << text;
    return dir.file(name);
  }
  static std::string row(const std::string& key, int n) {
    std::ostringstream s;
    s << key << ":";
    for (int i = 0; i < n; ++i)
      s << " " << (i % 5 == 0 ? 1.0 : 0.0);
    return s.str() + "\n";
  }
  void expectError(const std::string& path, const std::vector<std::string>& words) {
    try {
      msf::loadCalibration(path);
      FAIL() << "expected an error for " << path;
    } catch (const msf::Error& e) {
      for (const auto& w : words)
        EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << "'" << w << "' not in: " << e.what();
    }
  }
};

TEST_F(CalibrationErrors, MissingKeyNamesKeyAndFile) {
  const auto path = write("calib.txt", row("P0", 12) + row("P1", 12) + row("P3", 12) + row("Tr", 12));
  expectError(path, {"'P2'", path});
}

TEST_F(CalibrationErrors, CamerasOnlyLoadsAndTheLidarStagesSayWhatIsMissing) {
  // The KITTI stereo benchmarks' calib files: P0..P3, no Tr, no image beside them.
  const auto path = write("calib.txt", row("P0", 12) + row("P1", 12) + row("P2", 12) + row("P3", 12));
  const msf::Calibration c = msf::loadCalibration(path);
  EXPECT_FALSE(c.has_velodyne);
  EXPECT_EQ(c.image_size, cv::Size(0, 0));
  try {
    c.requireVelodyne();
    FAIL();
  } catch (const msf::CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras only"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_TRUE(msf::loadCalibration(write("full.txt", row("P0", 12) + row("P1", 12) + row("P2", 12) + row("P3", 12) +
                                                         row("Tr", 12)))
                  .has_velodyne);
  // Written back without a Tr it does not have, in both formats.
  msf::Calibration sized = msf::loadCalibration(path, {1242, 375});
  EXPECT_EQ(sized.image_size, cv::Size(1242, 375));
  msf::saveCalibrationYaml(sized, dir.file("camera.yaml"));
  msf::saveOdometryCalibration(sized, dir.file("again.txt"));
  EXPECT_FALSE(msf::loadCalibration(dir.file("camera.yaml")).has_velodyne);
  EXPECT_EQ(msf::loadCalibration(dir.file("camera.yaml")).image_size, cv::Size(1242, 375));
  EXPECT_FALSE(msf::loadCalibration(dir.file("again.txt")).has_velodyne);
  // A given size that contradicts the calibration's own is an error naming both.
  try {
    msf::loadCalibration(dir.file("camera.yaml"), {1000, 375});
    FAIL();
  } catch (const msf::CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("1000x375 given"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1242x375"), std::string::npos) << e.what();
  }
}

TEST(Calibration, ImageSizeText) {
  EXPECT_EQ(msf::parseImageSize("1242x375"), cv::Size(1242, 375));
  EXPECT_EQ(msf::parseImageSize(""), cv::Size(0, 0));
  for (const char* bad : {"1242", "1242x", "x375", "0x375", "-5x3", "12x3x4", "1242*375", "12.5x3", " 12x3", "+12x3"})
    EXPECT_THROW(msf::parseImageSize(bad), msf::InvalidInputError) << bad;
  // Beyond an int, and beyond the limit: the message names the size given, not a wrapped one.
  EXPECT_NE(msf::test::errorOf([] { msf::parseImageSize("99999999999x5"); })
                .find("image size 99999999999x5 is outside 1x1 .. 8192x8192"),
            std::string::npos);
  EXPECT_THROW(msf::parseImageSize("8193x375"), msf::InvalidInputError);
  EXPECT_EQ(msf::parseImageSize("8192x2048"), cv::Size(8192, 2048));
  EXPECT_NE(msf::test::errorOf([] { msf::parseImageSize("8192x8192"); }).find("has 67108864 pixels, more than the"),
            std::string::npos);
}

TEST_F(CalibrationErrors, WrongMatrixSizeNamesKeyAndCount) {
  const auto path = write("calib.txt", row("P0", 12) + row("P1", 11) + row("P2", 12) + row("P3", 12) + row("Tr", 12));
  expectError(path, {"'P1'", "11 values", path});
}

TEST_F(CalibrationErrors, ObjectCalibMissingRectification) {
  const auto path = write("000000.txt", row("P0", 12) + row("P1", 12) + row("P2", 12) + row("P3", 12) +
                                            row("Tr_velo_to_cam", 12));
  expectError(path, {"'R0_rect'", path});
}

TEST_F(CalibrationErrors, RawFolderWithoutVelodyneCalibration) {
  write("calib_cam_to_cam.txt", row("P_rect_00", 12) + row("P_rect_01", 12) + row("P_rect_02", 12) +
                                    row("P_rect_03", 12) + row("R_rect_00", 9) + row("S_rect_00", 2));
  expectError(dir.path(), {"calib_velo_to_cam.txt", "does not exist"});
}

TEST_F(CalibrationErrors, YamlWithWrongShape) {
  const auto path = write("cam.yaml", "%YAML:1.0\nP0: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                                      "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n");
  expectError(path, {"'P0'", "3x3"});
}

TEST_F(CalibrationErrors, MissingPathAndUnknownContent) {
  expectError("/nonexistent/calib.txt", {"/nonexistent/calib.txt", "does not exist"});
  expectError(write("notes.txt", "hello: world\n"), {"not a KITTI"});
}

} // namespace
