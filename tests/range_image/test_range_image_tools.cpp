// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_project and msf_interpolate on a real scan, and their errors.
#include <msf/io/cloud_io.h>
#include <msf/range_image/point_types.h>

#include <test_support.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

namespace {

std::string odometry() { return msf::test::kittiDir() + "/odometry/sequences/04"; }
std::string q(const std::string& s) { return "'" + s + "'"; }

TEST(RangeImageTools, ProjectThenInterpolate) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir tmp;
  const std::string sparse = tmp.file("sparse.pcd"), dense = tmp.file("dense.pcd");
  auto r = msf::test::runTool("msf_project", q(odometry() + "/velodyne/000000.bin") + " " + q(sparse) + " -calib " +
                                                 q(odometry() + "/calib.txt"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<pcl::PointXYZI> projected;
  msf::loadCloud(sparse, projected);
  EXPECT_EQ(projected.width, 1226u);
  EXPECT_EQ(projected.height, 370u);

  r = msf::test::runTool("msf_interpolate", q(sparse) + " " + q(dense) + " -max_gap 48");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<msf::PointXYZID> interpolated;
  msf::loadCloud(dense, interpolated); // fails without the distance field
  ASSERT_EQ(interpolated.width, 1226u);
  ASSERT_EQ(interpolated.height, 370u);
  std::size_t valid = 0, real = 0;
  for (std::size_t i = 0; i < interpolated.size(); ++i) {
    valid += std::isfinite(interpolated[i].z);
    if (std::isfinite(projected[i].z)) {
      ++real;
      EXPECT_EQ(interpolated[i].z, projected[i].z);
      EXPECT_EQ(interpolated[i].distance, 0.f);
    }
  }
  EXPECT_GT(valid, 10 * real);

  // The baselines run through the same tool.
  r = msf::test::runTool("msf_interpolate", q(sparse) + " " + q(tmp.file("ip.pcd")) + " -method ipbasic");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // From the scan itself, with the calibration.
  r = msf::test::runTool("msf_interpolate", q(odometry() + "/velodyne/000000.bin") + " " + q(tmp.file("scan.pcd")) +
                                                " -calib " + q(odometry() + "/calib.txt") + " -no_gaussian");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(msf::test::fileExists(tmp.file("scan.pcd")));
}

TEST(RangeImageTools, ErrorsNameTheProblemAndLeaveNoFile) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir tmp;
  const std::string scan = q(odometry() + "/velodyne/000000.bin");
  const std::string out = q(tmp.file("out.pcd"));
  struct Case {
    const char* tool;
    std::string args;
    const char* message;
  };
  const std::vector<Case> cases{
      {"msf_project", scan + " " + out, "-calib"},
      {"msf_project", scan + " " + out + " -calib /nonexistent/calib.txt", "/nonexistent/calib.txt"},
      {"msf_project", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -camera 7", "projection.camera"},
      {"msf_project", q(odometry() + "/velodyne/missing.bin") + " " + out + " -calib " + q(odometry() + "/calib.txt"),
       "missing.bin"},
      {"msf_project", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -bogus 1", "-bogus"},
      {"msf_interpolate", scan + " " + out, "-calib"},
      {"msf_interpolate", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -method spline", "spline"},
      {"msf_interpolate", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -short_gap 9 -max_gap 4",
       "short_gap_px"},
      {"msf_interpolate", scan + " " + q(tmp.file("out.ply")), "out.ply"},
      {"msf_project", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -image_size 1000x370",
       "1000x370 given"},
      {"msf_project", scan + " " + out + " -calib " + q(odometry() + "/calib.txt") + " -image_size 12x", "'12x'"},
  };
  for (const auto& c : cases) {
    const auto r = msf::test::runTool(c.tool, c.args);
    EXPECT_NE(r.exit_code, 0) << c.tool << " " << c.args;
    EXPECT_NE(r.err.find(std::string(c.tool) + ": error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.tool << " " << c.args << ": " << r.err;
    EXPECT_EQ(msf::test::countEntries(tmp.path()), 0u) << c.tool << " " << c.args;
  }
}

TEST(RangeImageTools, CalibrationsWithoutAnImageOrATr) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir tmp;
  std::ifstream in(odometry() + "/calib.txt");
  std::string line, cameras, all;
  for (int n = 0; std::getline(in, line); ++n) {
    all += line + "\n";
    if (n < 4)
      cameras += line + "\n"; // P0..P3: a KITTI stereo benchmark's file
  }
  std::ofstream(tmp.file("cameras.txt")) << cameras;
  std::ofstream(tmp.file("calib.txt")) << all; // no image_0 beside it
  const std::string scan = q(odometry() + "/velodyne/000000.bin");
  auto r = msf::test::runTool("msf_project", scan + " " + q(tmp.file("a.pcd")) + " -calib " + q(tmp.file("cameras.txt")));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("cameras only"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_project", scan + " " + q(tmp.file("a.pcd")) + " -calib " + q(tmp.file("calib.txt")));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-image_size WxH"), std::string::npos) << r.err;
  // Given the size, the same projection as with the images beside the calibration.
  r = msf::test::runTool("msf_project", scan + " " + q(tmp.file("b.pcd")) + " -calib " + q(tmp.file("calib.txt")) +
                                            " -image_size 1226x370");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = msf::test::runTool("msf_project", scan + " " + q(tmp.file("c.pcd")) + " -calib " + q(odometry() + "/calib.txt"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<pcl::PointXYZ> b, c;
  msf::loadCloud(tmp.file("b.pcd"), b);
  msf::loadCloud(tmp.file("c.pcd"), c);
  ASSERT_EQ(b.size(), c.size());
  EXPECT_EQ(b.width, 1226u);
  for (std::size_t i = 0; i < b.size(); ++i)
    ASSERT_TRUE(std::isnan(b[i].z) ? std::isnan(c[i].z) : b[i].z == c[i].z) << i;
}

TEST(RangeImageTools, HelpExitsZero) {
  for (const char* tool : {"msf_project", "msf_interpolate", "msf_holdout"}) {
    const auto r = msf::test::runTool(tool, "-h");
    EXPECT_EQ(r.exit_code, 0) << tool;
    EXPECT_NE(r.err.find("Syntax"), std::string::npos) << tool;
  }
}

} // namespace
