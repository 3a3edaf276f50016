// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Earlier scans in the current view: what they add lies on the surfaces the current view sees;
// a moving object's earlier returns and returns hidden from the current view are left out.
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/scan_history.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZI>;

struct Box {
  Eigen::Vector3d min, max;
};

/// Boxes above a ground plane at z = -1.7 m (the LiDAR at z = 0), in the world frame.
struct Scene {
  std::vector<Box> boxes;

  /// Distance along the unit ray from `origin` to the first surface; +inf when none.
  double cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& ray) const {
    double best = ray.z() < 0.0 ? (-1.7 - origin.z()) / ray.z() : std::numeric_limits<double>::infinity();
    for (const Box& b : boxes) {
      double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        const double inv = 1.0 / ray[a];
        double near = (b.min[a] - origin[a]) * inv, far = (b.max[a] - origin[a]) * inv;
        if (near > far)
          std::swap(near, far);
        t0 = std::max(t0, near);
        t1 = std::min(t1, far);
      }
      if (t0 <= t1 && t0 > 0.0)
        best = std::min(best, t0);
    }
    return best;
  }

  /// A spinning LiDAR at `origin` (axes of the world): rings every 3 degrees from -21 to +9, a
  /// return every quarter degree of azimuth within +-35 degrees, returns within 80 m.
  Cloud scan(const Eigen::Vector3d& origin) const {
    Cloud cloud;
    for (int ring = 0; ring <= 10; ++ring)
      for (double azimuth = -35.0; azimuth <= 35.0; azimuth += 0.25) {
        const double e = (-21.0 + 3.0 * ring) * M_PI / 180.0, a = azimuth * M_PI / 180.0;
        const Eigen::Vector3d ray(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        const double range = cast(origin, ray);
        if (range < 80.0) {
          pcl::PointXYZI p;
          p.getVector3fMap() = (range * ray).cast<float>();
          p.intensity = 1.f;
          cloud.push_back(p);
        }
      }
    return cloud;
  }
};

Eigen::Isometry3d at(const Eigen::Vector3d& origin) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = origin;
  return T;
}

/// The points of `out` after the first `current` ones: what the earlier scans added.
std::vector<Eigen::Vector3d> addedPoints(const Cloud& out, std::size_t current) {
  std::vector<Eigen::Vector3d> added;
  for (std::size_t i = current; i < out.size(); ++i)
    added.push_back(out[i].getVector3fMap().cast<double>());
  return added;
}

/// Every added point lies on the surface the current LiDAR sees along its ray or a ray within a
/// pixel and a half of it (a silhouette's edge lies between two rings), within the agreement that
/// ScanHistory allows (its defaults, for scans up to 3 frames old).
void expectOnVisibleSurface(const Scene& scene, const Eigen::Vector3d& origin,
                            const std::vector<Eigen::Vector3d>& added) {
  const double slack_rad = 0.015; // 1.5 px of smallCamera
  for (const auto& p : added) {
    const Eigen::Vector3d ray = p.normalized();
    const Eigen::Vector3d side = ray.cross(Eigen::Vector3d::UnitZ()).normalized(), up = side.cross(ray);
    bool on_surface = false;
    const Eigen::Vector3d offsets[] = {Eigen::Vector3d::Zero(), side, -side, up, -up};
    for (const Eigen::Vector3d& offset : offsets) {
      const double visible = scene.cast(origin, (ray + slack_rad * offset).normalized());
      on_surface = on_surface || std::abs(p.norm() - visible) <= 0.1 + 0.03 * visible;
    }
    EXPECT_TRUE(on_surface) << "added point (" << p.transpose() << ") is off the visible surface";
  }
}

msf::ScanHistoryConfig historyOf(int scans) {
  msf::ScanHistoryConfig config;
  config.scans = scans;
  return config;
}

/// Drives `steps` frames along `step` per frame through `scene` (moved by `scene_step` per frame
/// first), and returns the last frame's densified scan; `origin` ends at the last frame's.
Cloud drive(msf::ScanHistory& history, Scene scene, const Eigen::Vector3d& start, const Eigen::Vector3d& step,
            int steps, Eigen::Vector3d& origin, std::size_t& current, const Eigen::Vector3d& box0_step = {0, 0, 0},
            Scene* last_scene = nullptr) {
  Cloud out;
  for (int k = 0; k < steps; ++k) {
    origin = start + k * step;
    if (k > 0 && !scene.boxes.empty()) {
      scene.boxes[0].min += box0_step;
      scene.boxes[0].max += box0_step;
    }
    const Cloud scan = scene.scan(origin);
    history.densify(scan, at(origin), out);
    current = scan.size();
  }
  if (last_scene)
    *last_scene = scene;
  return out;
}

TEST(ScanHistory, AnEdgeBetweenTheCurrentRingsComesFromAnEarlierScan) {
  // A low wall 15 m ahead whose top (z = -1 m) lies between the current rings at -3 and -6
  // degrees; 5 m further back, the -3 degree ring hit the wall just below its top.
  Scene scene;
  scene.boxes.push_back({{15, -5, -1.7}, {16, 5, -1.0}});
  scene.boxes.push_back({{40, -30, -1.7}, {41, 30, 20}});
  msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), historyOf(2));
  Eigen::Vector3d origin;
  std::size_t current = 0;
  const Cloud out = drive(history, scene, {-5, 0, 0}, {5, 0, 0}, 2, origin, current);
  const auto added = addedPoints(out, current);
  ASSERT_FALSE(added.empty());
  expectOnVisibleSurface(scene, origin, added);
  // The current scan's highest return on the wall is at z = -1.57 (the -6 degree ring).
  double highest_current = -10.0, highest_added = -10.0;
  for (std::size_t i = 0; i < current; ++i)
    if (out[i].x < 15.5f)
      highest_current = std::max(highest_current, static_cast<double>(out[i].z));
  for (const auto& p : added)
    if (p.x() < 15.5)
      highest_added = std::max(highest_added, p.z());
  EXPECT_LT(highest_current, -1.5);
  EXPECT_GT(highest_added, -1.1);
  EXPECT_EQ(history.lastStats().added, added.size());

  // Interpolated with them, the wall reaches up to its top in the image.
  msf::LidarCompletion lidar(msf::test::smallCalibration());
  cv::Mat alone, with_earlier;
  Cloud scan;
  scan.insert(scan.end(), out.begin(), out.begin() + static_cast<long>(current));
  lidar.computeDepth(scan, alone);
  lidar.computeDepth(out, with_earlier);
  const msf::PinholeCamera camera = msf::test::smallCamera();
  const int u = static_cast<int>(camera.cx), v = static_cast<int>(std::lround(camera.cy + camera.fy * 1.04 / 15.0));
  EXPECT_NEAR(with_earlier.at<float>(v, u), 15.f, 0.1f);
  EXPECT_GT(std::abs(alone.at<float>(v, u) - 15.f), 0.5f) << "the test does not need the earlier scan";
}

TEST(ScanHistory, AMovingCarsEarlierReturnsStayOffWhereItWas) {
  // A car 10 m ahead driving at the LiDAR's speed, then one crossing from the right.
  for (const Eigen::Vector3d& car_step : {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(2, 1.5, 0)}) {
    Scene scene;
    scene.boxes.push_back({{10, -4, -1.4}, {14, -2, 0.0}});
    scene.boxes.push_back({{40, -30, -1.7}, {41, 30, 20}});
    msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), historyOf(3));
    Eigen::Vector3d origin;
    std::size_t current = 0;
    Scene last;
    const Cloud out = drive(history, scene, {0, 0, 0}, {2, 0, 0}, 4, origin, current, car_step, &last);
    const auto added = addedPoints(out, current);
    EXPECT_FALSE(added.empty()); // the ground and the wall still gain
    // Where the car was, nothing: each added point lies on what the current view sees (the car's
    // earlier returns at its rear corner coincide with it now, within the agreement).
    expectOnVisibleSurface(last, origin, added);
    std::size_t where_the_car_was = 0;
    for (const auto& p : added)
      where_the_car_was += p.x() < 9.5 && p.y() < -1.0 && p.y() > -4.5 && p.z() > -1.4;
    EXPECT_EQ(where_the_car_was, 0u);
  }
}

TEST(ScanHistory, AReturnHiddenFromTheCurrentViewIsLeftOut) {
  // The LiDAR comes 15 m forward and 4 m to the right: the far wall it saw past the near wall's
  // edge is behind that edge now, between the current rings.
  Scene scene;
  scene.boxes.push_back({{8, -10, -1.7}, {9, 1, 5}});
  scene.boxes.push_back({{30, -30, -1.7}, {31, 30, 20}});
  msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), historyOf(2));
  Eigen::Vector3d origin;
  std::size_t current = 0;
  const Cloud out = drive(history, scene, {-15, 4, 0}, {15, -4, 0}, 2, origin, current);
  EXPECT_GT(history.lastStats().disagreeing, 10u);
  // The near wall's edge hides the far wall up to y = 3.75 m; within a ring's gap of the edge the
  // current rings cannot tell which of the two a pixel sees.
  for (const auto& p : addedPoints(out, current))
    EXPECT_FALSE(p.x() > 20.0 && p.y() < 3.0) << "a return of the far wall behind the near one: " << p.transpose();
}

TEST(ScanHistory, ZeroScansIsTheCurrentScanAlone) {
  Scene scene;
  scene.boxes.push_back({{20, -30, -1.7}, {21, 30, 20}});
  msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), historyOf(0));
  Eigen::Vector3d origin;
  std::size_t current = 0;
  const Cloud out = drive(history, scene, {0, 0, 0}, {1, 0, 0}, 3, origin, current);
  EXPECT_EQ(out.size(), current);
  EXPECT_EQ(history.size(), 0u);
}

TEST(ScanHistory, KeepsTheLastScansOnly) {
  Scene scene;
  scene.boxes.push_back({{20, -30, -1.7}, {21, 30, 20}});
  msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), historyOf(2));
  Eigen::Vector3d origin;
  std::size_t current = 0;
  drive(history, scene, {0, 0, 0}, {1, 0, 0}, 5, origin, current);
  EXPECT_EQ(history.size(), 2u);
  history.clear();
  EXPECT_EQ(history.size(), 0u);
}

TEST(ScanHistory, RefusesABadConfig) {
  msf::ScanHistoryConfig config;
  config.scans = -1;
  try {
    msf::ScanHistory history(msf::test::smallCalibration(), msf::ProjectionConfig(), config);
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("accumulation.scans"), std::string::npos) << e.what();
  }
}

} // namespace
