// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/common/config.h>
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_rasterizer.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace msf {
namespace {

/// The camera drives along +z (y down), 1 m per frame.
Eigen::Isometry3d drivePose(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().z() = i;
  return T;
}

/// A road 1.65 m below the camera and a wall 4 m to its right, 6 m high; with `van`, a van
/// 2.4 m high (0.75 m above the camera) stopped in the lane with its rear 12 m on.
AnalyticScene road(bool van) {
  AnalyticScene s;
  s.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.65);
  s.addBox(Eigen::Vector3d(4.2, -1.35, 20), Eigen::Vector3d(0.2, 3, 30));
  if (van)
    s.addBox(Eigen::Vector3d(0, 1.65 - 1.2, 14.5), Eigen::Vector3d(0.9, 1.2, 2.5));
  return s;
}

/// The open sky of a frame of an analytic scene: the pixels above the horizon whose ray meets
/// nothing within 80 m.
cv::Mat openSky(const AnalyticScene& scene, const PinholeCamera& camera, const Eigen::Isometry3d& pose) {
  const cv::Mat far = scene.renderDepth(camera, pose, 80.0);
  cv::Mat sky = far == 0.f;
  sky.rowRange(static_cast<int>(camera.cy), sky.rows).setTo(0);
  return sky;
}

/// The share of a frame's open sky that the mesh covers (evaluation protocol 6).
double skyCovered(const TriangleMesh& mesh, const cv::Mat& sky, const PinholeCamera& camera,
                  const Eigen::Isometry3d& pose) {
  cv::Mat rendered;
  MeshRasterizer().render(mesh, camera, pose, rendered);
  return cv::countNonZero(sky & (rendered > 0.f)) / static_cast<double>(std::max(1, cv::countNonZero(sky)));
}

struct DriveResult {
  double sky_covered = 0;      ///< at the last frame
  std::size_t van_top = 0;     ///< vertices of the van's ghost above the camera
  std::size_t wall = 0;        ///< vertices of the wall
  std::size_t wall_upper = 0;  ///< of those, more than 0.5 m above the camera
};

/// What carveSky takes: NaN off `mask`, on it the depth that bounds its column's rays (`bound`,
/// one per column) or +inf, the whole ray (where `bound` is empty or 0).
cv::Mat skyDepth(const cv::Mat& mask, const std::vector<float>& bound = {}) {
  cv::Mat sky_depth(mask.size(), CV_32FC1, cv::Scalar(std::nanf("")));
  for (int u = 0; u < mask.cols; ++u) {
    const float b = bound.empty() ? 0.f : bound[static_cast<std::size_t>(u)];
    sky_depth.col(u).setTo(b > 0.f ? b : std::numeric_limits<float>::infinity(), mask.col(u));
  }
  return sky_depth;
}

/// What a frame's sky carving is given (carveSky's sky_depth).
using SkyOfFrame = std::function<cv::Mat(const AnalyticScene&, const PinholeCamera&, const Eigen::Isometry3d&)>;

cv::Mat trueSky(const AnalyticScene& scene, const PinholeCamera& camera, const Eigen::Isometry3d& pose) {
  return skyDepth(openSky(scene, camera, pose));
}

/// Frames 0-2 see the van; it drives off, and frames 3-8 see the road behind. What the rays
/// through its upper part meet is the sky, which has no depth.
DriveResult driveAfterTheVan(bool sky_carving, const SkyOfFrame& sky_of = trueSky) {
  const PinholeCamera camera = test::kittiCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.sky_carving = sky_carving;
  TsdfIntegrator integrator(volume, config);
  for (int i = 0; i <= 8; ++i) {
    const AnalyticScene scene = road(i <= 2);
    const DepthFrame frame = test::renderFrame(scene, camera, drivePose(i), 0.0);
    integrator.integrate(frame, drivePose(i));
    integrator.carveSky(sky_of(scene, camera, drivePose(i)), camera, drivePose(i), 1111.f);
  }
  DriveResult r;
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  r.sky_covered = skyCovered(mesh, openSky(road(false), camera, drivePose(8)), camera, drivePose(8));
  for (const auto& v : mesh.vertices) {
    r.van_top += std::abs(v.x()) < 1.2f && v.y() < 0.f && v.z() > 11.f && v.z() < 18.f;
    const bool wall = v.x() > 3.8f && v.x() < 4.2f && v.z() > 10.f && v.z() < 25.f;
    r.wall += wall;
    r.wall_upper += wall && v.y() < -0.5f;
  }
  std::printf("  sky carving %d: sky covered %.4f, van top %zu vertices, wall %zu (upper %zu)\n", sky_carving,
              r.sky_covered, r.van_top, r.wall, r.wall_upper);
  return r;
}

TEST(SkyCarving, ClearsTheGhostThatOnlyTheSkyLooksThrough) {
  const DriveResult without = driveAfterTheVan(false), with = driveAfterTheVan(true);
  // Without: the van's upper part stays, a sheet over the sky 4 m ahead of the last frame.
  EXPECT_GT(without.van_top, 80u); // its rear, 1.8 m x 0.75 m: one vertex per 0.1 m voxel
  EXPECT_GT(without.sky_covered, 0.05);
  // With: the sheet over the sky shrinks tenfold, and the wall the sky runs along is whole.
  // Part of the van's top stays: what no sky ray passes through is not carved.
  EXPECT_LT(with.sky_covered, without.sky_covered / 10);
  EXPECT_LT(with.van_top, without.van_top * 2 / 3);
  EXPECT_GE(with.wall, without.wall * 99 / 100);
}

/// A mask that errs as SkyMask does on a blank façade: every pixel above the horizon.
cv::Mat everythingAboveTheHorizon(const PinholeCamera& camera) {
  cv::Mat sky(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  sky.rowRange(0, static_cast<int>(camera.cy)).setTo(255);
  return sky;
}

/// Per column, the depth of the highest return a LiDAR whose top ring looks 2 degrees up gets
/// from `scene` (0: none), as SkyMask::topReturnDepth gives it.
std::vector<float> topReturnDepth(const AnalyticScene& scene, const PinholeCamera& camera,
                                  const Eigen::Isometry3d& pose) {
  const cv::Mat depth = scene.renderDepth(camera, pose, 80.0);
  const int top_ring_row = static_cast<int>(camera.cy - camera.fy * std::tan(2.0 * M_PI / 180.0));
  std::vector<float> top(static_cast<std::size_t>(camera.width), 0.f);
  for (int u = 0; u < camera.width; ++u)
    for (int v = top_ring_row; v < depth.rows && top[static_cast<std::size_t>(u)] == 0.f; ++v)
      top[static_cast<std::size_t>(u)] = depth.at<float>(v, u);
  return top;
}

TEST(SkyCarving, KeepsAWallTheMaskTakesForSkyInFrontOfItsReturns) {
  // The van's frames, then the road behind it, as in the drive above; but the mask also takes the
  // wall above the LiDAR's top ring for sky. Bounded by each column's highest return, the sky's
  // rays stop in front of the wall (a vertical plane keeps one depth down a column) and still
  // pass through the van's ghost, which hangs in front of the returns beyond it.
  const auto unboundedSky = [](const AnalyticScene&, const PinholeCamera& camera, const Eigen::Isometry3d&) {
    return skyDepth(everythingAboveTheHorizon(camera));
  };
  const auto boundedSky = [](const AnalyticScene& scene, const PinholeCamera& camera, const Eigen::Isometry3d& pose) {
    return skyDepth(everythingAboveTheHorizon(camera), topReturnDepth(scene, camera, pose));
  };
  const DriveResult truth = driveAfterTheVan(false), unbounded = driveAfterTheVan(true, unboundedSky),
                    bounded = driveAfterTheVan(true, boundedSky);
  ASSERT_GT(truth.wall_upper, 500u);
  EXPECT_LT(unbounded.wall_upper, truth.wall_upper / 10); // the mask's error erases the wall
  EXPECT_GE(bounded.wall_upper, truth.wall_upper * 98 / 100);
  EXPECT_LT(bounded.sky_covered, truth.sky_covered / 10); // and the ghost still goes
  EXPECT_LT(bounded.van_top, truth.van_top * 2 / 3);
}

/// A wall to the right, 4 m off the camera's path and 2.5 m above it (`widened`: its top 0.4 m
/// higher, as a far frame's facade extension can carry it over what stands behind).
AnalyticScene lowWall(bool widened) {
  AnalyticScene s;
  s.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.65);
  const double top = widened ? 2.9 : 2.5;
  s.addBox(Eigen::Vector3d(4.2, (1.65 - top) / 2, 25), Eigen::Vector3d(0.2, (1.65 + top) / 2, 20));
  return s;
}

TEST(SkyCarving, TheClearSkyClearsAWallsWidenedTopThatLiesAtItsReturnsDepth) {
  // Frames 0-2 integrate the wall 0.4 m too high; frames 3-6 see its true top against the sky. A
  // sky ray just over the top meets the widened band at the depth of the column's highest return
  // (the wall's own), where the bound stops; the clear sky's rays go on through it.
  const PinholeCamera camera = test::kittiCamera();
  auto drive = [&](bool clear) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config config;
    TsdfIntegrator integrator(volume, config);
    for (int i = 0; i <= 6; ++i) {
      const AnalyticScene scene = lowWall(i <= 2);
      integrator.integrate(test::renderFrame(scene, camera, drivePose(i), 0.0), drivePose(i));
      if (i <= 2)
        continue;
      const cv::Mat sky = openSky(scene, camera, drivePose(i));
      const std::vector<float> bound = clear ? std::vector<float>() : topReturnDepth(scene, camera, drivePose(i));
      integrator.carveSky(skyDepth(sky, bound), camera, drivePose(i), 1111.f);
    }
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    std::size_t band = 0, wall = 0;
    for (const auto& v : mesh.vertices) {
      if (!(v.x() > 3.8f && v.x() < 4.2f && v.z() > 16.f && v.z() < 21.f))
        continue;
      band += v.y() < -2.6f;
      wall += v.y() > -2.4f && v.y() < 0.f;
    }
    std::printf("  clear sky %d: band %zu vertices, wall %zu\n", clear, band, wall);
    return std::make_pair(band, wall);
  };
  const auto [band_bounded, wall_bounded] = drive(false);
  const auto [band_clear, wall_clear] = drive(true);
  EXPECT_GT(band_bounded, 100u); // the bound keeps it: 0.4 m x 5 m of face
  EXPECT_LT(band_clear, band_bounded / 10);
  EXPECT_GT(wall_bounded, 1000u);
  EXPECT_GE(wall_clear, wall_bounded * 99 / 100); // the wall below its top stays whole
}

TEST(SkyCarving, CarvesOnlyAlongTheSkysRays) {
  // A wall seen from the street; a mask that holds every pixel but the wall's leaves it whole,
  // one that holds it too clears it.
  const PinholeCamera camera = test::kittiCamera();
  const AnalyticScene scene = road(false);
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.sky_carving = true;
  TsdfIntegrator integrator(volume, config);
  integrator.integrate(test::renderFrame(scene, camera, drivePose(0), 0.0), drivePose(0));
  auto wallVertices = [&] {
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    std::size_t n = 0;
    for (const auto& v : mesh.vertices)
      n += v.x() > 3.8f && v.x() < 4.2f && v.y() < 0.f;
    return n;
  };
  const std::size_t before = wallVertices();
  const cv::Mat depth = scene.renderDepth(camera, drivePose(0), 20.0);
  cv::Mat wall_pixels(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      wall_pixels.at<std::uint8_t>(v, u) = z > 0.f && (u - camera.cx) / camera.fx * z > 3.9 ? 255 : 0;
    }
  integrator.carveSky(skyDepth(~wall_pixels), camera, drivePose(0), 1111.f);
  EXPECT_GE(wallVertices(), before * 99 / 100); // a voxel at its top edge may round into the sky
  EXPECT_GT(before, 1000u);
  integrator.carveSky(skyDepth(cv::Mat(depth.size(), CV_8UC1, cv::Scalar(255))), camera, drivePose(0), 1111.f);
  EXPECT_LT(wallVertices(), before / 20);
}

TEST(SkyCarving, OffEmptyOrRefused) {
  const PinholeCamera camera = test::kittiCamera();
  const AnalyticScene scene = road(true);
  const DepthFrame frame = test::renderFrame(scene, camera, drivePose(0), 0.0);
  const cv::Mat everything = skyDepth(cv::Mat(camera.height, camera.width, CV_8UC1, cv::Scalar(255)));
  auto vertices = [](const TsdfVolume& volume) {
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    return mesh.vertices.size();
  };
  for (const bool space_carving : {false, true}) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config config;
    config.space_carving = space_carving;
    config.sky_carving = !space_carving; // sky carving needs both
    TsdfIntegrator integrator(volume, config);
    integrator.integrate(frame, drivePose(0));
    const std::size_t before = vertices(volume);
    integrator.carveSky(everything, camera, drivePose(0), 1111.f);
    EXPECT_EQ(vertices(volume), before);
    TsdfIntegrator::FreeSpace free; // carving off, integrateFrame reads no sky depth, a bad one neither
    free.weight = 1111.f;
    free.sky_depth = cv::Mat(10, 10, CV_32FC1, cv::Scalar(0.f));
    free.sky_camera = camera;
    EXPECT_NO_THROW(integrator.integrateFrame(frame, drivePose(1), free));
  }
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.sky_carving = true;
  TsdfIntegrator integrator(volume, config);
  integrator.integrate(frame, drivePose(0));
  const std::size_t before = vertices(volume);
  integrator.carveSky(cv::Mat(), camera, drivePose(0), 1111.f); // no sky: nothing
  integrator.carveSky(skyDepth(cv::Mat(camera.height, camera.width, CV_8UC1, cv::Scalar(0))), camera, drivePose(0),
                      1111.f);
  EXPECT_EQ(vertices(volume), before);
  EXPECT_EQ(test::errorOf([&] {
              integrator.carveSky(cv::Mat(10, 10, CV_32FC1, cv::Scalar(5.f)), camera, drivePose(0), 1111.f);
            }),
            "the sky depth must be CV_32FC1 of the camera's 1241x376, not 10x10 CV_32FC1");
  EXPECT_EQ(test::errorOf([&] {
              integrator.carveSky(cv::Mat(camera.height, camera.width, CV_8UC1, cv::Scalar(255)), camera, drivePose(0),
                                  1111.f);
            }),
            "the sky depth must be CV_32FC1 of the camera's 1241x376, not 1241x376 CV_8UC1");
  for (const float bound : {0.f, -2.f, -std::numeric_limits<float>::infinity()}) {
    cv::Mat sky_depth = everything.clone();
    sky_depth.at<float>(7, 30) = bound;
    const std::string error = test::errorOf([&] { integrator.carveSky(sky_depth, camera, drivePose(0), 1111.f); });
    EXPECT_EQ(error.rfind("the sky depth at pixel (30, 7) is ", 0), 0u) << error;
    EXPECT_NE(error.find("a pixel's bound is NaN (not sky), a depth > 0 or +inf"), std::string::npos) << error;
  }
  EXPECT_THROW(integrator.carveSky(everything, camera, drivePose(0), 0.f), InvalidInputError);
  EXPECT_THROW(integrator.carveSky(everything, camera, drivePose(0), std::nanf("")), InvalidInputError);
  EXPECT_EQ(vertices(volume), before);
}

TEST(SkyCarving, IsAConfigKey) {
  TsdfIntegrator::Config config;
  EXPECT_TRUE(config.sky_carving);
  ConfigFile::fromText("tsdf_integrator:\n  sky_carving: false\n", "c.yaml").read(config);
  EXPECT_FALSE(config.sky_carving);
  std::ostringstream printed;
  printConfig(printed, config);
  EXPECT_NE(printed.str().find("  sky_carving: false\n"), std::string::npos) << printed.str();
}

} // namespace
} // namespace msf
