// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/range_image/point_types.h>
#include <msf/stereo/point_types.h>

#include "test_support.h"

#include <opencv2/imgcodecs.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

namespace {

constexpr int kW = 8, kH = 6;

msf::Calibration calibration(int w = kW, int h = kH) {
  msf::Calibration c;
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  P(0, 0) = P(1, 1) = 500.0;
  P(0, 2) = w / 2.0;
  P(1, 2) = h / 2.0;
  P(2, 2) = 1.0;
  for (auto& p : c.P)
    p = P;
  c.P[1](0, 3) = -250.0;
  c.image_size = cv::Size(w, h);
  return c;
}

template <typename PointT>
pcl::PointCloud<PointT> cloudAt(int w, int h, float z, int missing_every) {
  pcl::PointCloud<PointT> cloud(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      PointT& p = cloud[static_cast<std::size_t>(v) * w + u];
      const bool valid = missing_every == 0 || (u + v) % missing_every != 0;
      p.x = valid ? (u - w / 2.f) * z / 500.f : std::numeric_limits<float>::quiet_NaN();
      p.y = valid ? (v - h / 2.f) * z / 500.f : std::numeric_limits<float>::quiet_NaN();
      p.z = valid ? z : std::numeric_limits<float>::quiet_NaN();
    }
  cloud.is_dense = missing_every == 0;
  return cloud;
}

struct Files {
  msf::test::TempDir dir;
  std::string calib = dir.file("calib.yaml"), lidar = dir.file("lidar.pcd"), stereo = dir.file("stereo.pcd"),
              out = dir.file("fused.pcd");
  Files() {
    msf::saveCalibrationYaml(calibration(), calib);
    auto l = cloudAt<msf::PointXYZID>(kW, kH, 10.f, 3);
    for (auto& p : l)
      p.distance = 1.f;
    msf::saveCloud(lidar, l);
    // 10.4 m: 0.96 px of disparity from the LiDAR's 10 m, within 3 sigma of the two (0.38 px), so averaged.
    auto s = cloudAt<msf::PointXYZRGBConfidence>(kW, kH, 10.4f, 4);
    for (auto& p : s) {
      p.confidence = 0.9f;
      p.r = 200;
    }
    msf::saveCloud(stereo, s);
  }
};

TEST(FuseTool, FusesTwoOrganizedCloudsWithBothMethods) {
  // Without the small holes' fill: a pixel neither cloud has stays NaN.
  Files f;
  std::ofstream(f.dir.file("no_fill.yaml")) << "%YAML:1.0\nfusion:\n  hole_fill_px: 0\n";
  for (const char* method : {"paper", "uncertainty"}) {
    const auto r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.out + " -calib " + f.calib +
                                                      " -method " + method + " -config " +
                                                      f.dir.file("no_fill.yaml") + " -overwrite");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pcl::PointCloud<msf::PointXYZRGBWeight> fused;
    msf::loadCloud(f.out, fused); // the file has x y z rgb weight
    ASSERT_EQ(fused.width, static_cast<std::uint32_t>(kW));
    ASSERT_EQ(fused.height, static_cast<std::uint32_t>(kH));
    for (int v = 0; v < kH; ++v)
      for (int u = 0; u < kW; ++u) {
        const bool lidar = (u + v) % 3 != 0, stereo = (u + v) % 4 != 0;
        const auto& p = fused.at(u, v);
        if (!lidar && !stereo) {
          EXPECT_TRUE(std::isnan(p.z));
          continue;
        }
        if (!lidar)
          EXPECT_FLOAT_EQ(p.z, 10.4f);
        else if (!stereo)
          EXPECT_FLOAT_EQ(p.z, 10.f);
        else {
          EXPECT_GT(p.z, 10.f);
          EXPECT_LT(p.z, 10.4f);
        }
        EXPECT_GT(p.weight, 0.f);
      }
  }
}

TEST(FuseTool, FillsTheSmallHolesAtWeightZeroAsTheEngine) {
  // fusion.hole_fill_px (8 by default): a pixel neither cloud has takes its row neighbour's
  // depth, at weight 0, which msf_integrate does not integrate.
  Files f;
  const auto r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.out + " -calib " + f.calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<msf::PointXYZRGBWeight> fused;
  msf::loadCloud(f.out, fused);
  int filled = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      if ((u + v) % 3 != 0 || (u + v) % 4 != 0)
        continue; // a depth of its own
      const auto& p = fused.at(u, v);
      ASSERT_TRUE(std::isfinite(p.z)) << "hole (" << u << ", " << v << ") not filled";
      EXPECT_GE(p.z, 10.f);
      EXPECT_LE(p.z, 10.4f);
      EXPECT_EQ(p.weight, 0.f);
      EXPECT_EQ(p.free_space_weight, 0.f);
      ++filled;
    }
  EXPECT_GT(filled, 0);
}

TEST(FuseTool, AcceptsCloudsWithoutDistanceOrConfidence) {
  Files f;
  msf::saveCloud(f.dir.file("plain_lidar.pcd"), cloudAt<pcl::PointXYZI>(kW, kH, 10.f, 0));
  msf::saveCloud(f.dir.file("plain_stereo.pcd"), cloudAt<pcl::PointXYZ>(kW, kH, 10.f, 0));
  const auto r = msf::test::runTool("msf_fuse", f.dir.file("plain_lidar.pcd") + " " + f.dir.file("plain_stereo.pcd") +
                                                    " " + f.out + " -calib " + f.calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("no field 'distance'"), std::string::npos) << r.err;
  pcl::PointCloud<pcl::PointXYZ> fused;
  msf::loadCloud(f.out, fused);
  EXPECT_FLOAT_EQ(fused.at(3, 3).z, 10.f);
}

TEST(FuseTool, TheLeftImageContinuesABlankWallUpward) {
  // A blank wall 10 m away: LiDAR returns on rows 30-59 of a 40x60 image, no stereo match.
  // With -left the fused cloud has the wall on every row, each point on its pixel's ray;
  // without it, nothing above the LiDAR.
  constexpr int w = 40, h = 60;
  Files f;
  msf::saveCalibrationYaml(calibration(w, h), f.calib); // the rig of these clouds
  auto lidar = cloudAt<msf::PointXYZID>(w, h, 10.f, 0);
  for (std::size_t i = 0; i < lidar.size(); ++i) {
    lidar[i].distance = 0.f;
    if (i < static_cast<std::size_t>(30 * w))
      lidar[i].x = lidar[i].y = lidar[i].z = std::numeric_limits<float>::quiet_NaN();
  }
  lidar.is_dense = false;
  msf::saveCloud(f.dir.file("wall_lidar.pcd"), lidar);
  auto stereo = cloudAt<msf::PointXYZRGBConfidence>(w, h, 10.f, 1); // (u + v) % 1 == 0: no point valid
  msf::saveCloud(f.dir.file("wall_stereo.pcd"), stereo);
  const std::string left = f.dir.file("left.png");
  ASSERT_TRUE(cv::imwrite(left, cv::Mat(h, w, CV_8UC1, cv::Scalar(120))));
  const std::string inputs = f.dir.file("wall_lidar.pcd") + " " + f.dir.file("wall_stereo.pcd") + " " + f.out;
  auto r = msf::test::runTool("msf_fuse", inputs + " -calib " + f.calib + " -left " + left);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PointCloud<msf::PointXYZRGBWeight> fused;
  msf::loadCloud(f.out, fused);
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < w; u += 13) {
      const auto& p = fused.at(u, v);
      ASSERT_NEAR(p.z, 10.f, 1e-4f) << u << "," << v;
      EXPECT_NEAR(p.x, (u - w / 2.f) * 10.f / 500.f, 1e-4f); // the calibration's principal point
      EXPECT_NEAR(p.y, (v - h / 2.f) * 10.f / 500.f, 1e-4f);
      EXPECT_GT(p.weight, 0.f);
      EXPECT_LT(p.weight, fused.at(u, 45).weight); // less sure than the LiDAR
    }
  r = msf::test::runTool("msf_fuse", inputs + " -calib " + f.calib + " -overwrite");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  msf::loadCloud(f.out, fused);
  EXPECT_FALSE(std::isfinite(fused.at(5, 10).z));
  // An image of another size than the clouds is refused, and nothing is written.
  ASSERT_TRUE(cv::imwrite(left, cv::Mat(h, w - 1, CV_8UC1, cv::Scalar(120))));
  std::remove(f.out.c_str());
  r = msf::test::runTool("msf_fuse", inputs + " -calib " + f.calib + " -left " + left);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-left image '" + left + "' is 39x60, the clouds are 40x60"), std::string::npos) << r.err;
  EXPECT_FALSE(msf::test::fileExists(f.out));
}

TEST(FuseTool, BadInputFailsAndLeavesNoOutput) {
  Files f;
  // Clouds of different sizes.
  msf::saveCloud(f.dir.file("small.pcd"), cloudAt<msf::PointXYZRGBConfidence>(kW - 1, kH, 10.f, 0));
  auto r = msf::test::runTool("msf_fuse", f.lidar + " " + f.dir.file("small.pcd") + " " + f.out + " -calib " + f.calib);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_fuse: error: DepthFusion: the LiDAR cloud is 8x6 but the stereo cloud is 7x6"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(msf::test::fileExists(f.out));
  // A missing input.
  r = msf::test::runTool("msf_fuse", f.dir.file("none.pcd") + " " + f.stereo + " " + f.out + " -calib " + f.calib);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("none.pcd"), std::string::npos) << r.err;
  // An unorganized cloud.
  pcl::PointCloud<pcl::PointXYZ> flat = cloudAt<pcl::PointXYZ>(kW * kH, 1, 10.f, 0);
  msf::saveCloud(f.dir.file("flat.pcd"), flat);
  r = msf::test::runTool("msf_fuse", f.lidar + " " + f.dir.file("flat.pcd") + " " + f.out + " -calib " + f.calib);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("not organized"), std::string::npos) << r.err;
  // Unknown method, missing -calib, unknown option.
  r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.out + " -calib " + f.calib + " -method mean");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("fusion method must be uncertainty | paper, not 'mean'"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.out);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-calib"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.out + " -calib " + f.calib + " -methd paper");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("unknown option '-methd'"), std::string::npos) << r.err;
  // An output folder that does not exist.
  r = msf::test::runTool("msf_fuse", f.lidar + " " + f.stereo + " " + f.dir.file("no/such/dir/out.pcd") + " -calib " + f.calib);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  EXPECT_FALSE(msf::test::fileExists(f.out));
  // Nothing but the inputs is left in the folder.
  EXPECT_EQ(msf::test::countEntries(f.dir.path()), 5u); // calib, lidar, stereo, small, flat: no temporaries
}

} // namespace
