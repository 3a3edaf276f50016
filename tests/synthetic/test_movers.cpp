// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Moving cars of the synthetic street: where the traffic drives, that the cameras and the
// LiDAR see each car where its box says at the frame's time, the moving mask, the static
// ground-truth mesh, the box file, and the static street left as it was.
#include "synthetic_fixture.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/io/image_io.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/moving_box.h>
#include <msf/synthetic/scene_mesh.h>
#include <msf/synthetic/scene_snapshot.h>
#include <msf/synthetic/street_scene.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <pcl/conversions.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace fs = std::filesystem;

namespace {

using msf::test::SharedStreet;
using namespace msf::synthetic;

bool isOncoming(const MovingObject& m) { return std::cos(m.yaw()) < 0.f; }

/// The time at which mover `m` (driving along z) is level with the cameras, at z = speed t.
double meetingTime(const MovingObject& m, double camera_speed_mps) {
  const double z0 = m.originAt(0.0).z, dz = m.originAt(1.0).z - z0; // its z per second
  return z0 / (camera_speed_mps - dz);
}

TEST(SyntheticTraffic, DefaultStreetHasACarAheadAndOncomingCarsThatPassInTheFirstHalf) {
  SyntheticConfig config;
  config.frames = 20;
  const double duration = (config.frames - 1) / config.frame_rate_hz;
  const Scene scene = buildStreetScene(config, duration * config.speed_mps);
  ASSERT_EQ(scene.movers.size(), 3u);
  std::uint32_t static_objects = 0;
  for (const Primitive& p : scene.primitives)
    static_objects = std::max(static_objects, p.object);
  int ahead = 0, oncoming = 0;
  std::set<std::uint32_t> ids;
  for (const MovingObject& m : scene.movers) {
    ids.insert(m.object());
    EXPECT_GT(m.object(), static_objects);
    ASSERT_EQ(m.solids().size(), 6u); // body, cabin, four tyres: the parked cars' solids
    for (const Primitive& solid : m.solids())
      EXPECT_EQ(solid.object, m.object());
    const V3 start = m.originAt(0.0);
    EXPECT_FLOAT_EQ(start.y, scene.layout.ground_y);
    if (isOncoming(m)) {
      ++oncoming;
      EXPECT_NEAR(start.x, scene.layout.leftLaneX(), 0.15 + 1e-5);
      EXPECT_DOUBLE_EQ(m.speedMps(), config.oncoming_car_speed_mps);
      EXPECT_LT(m.originAt(1.0).z, start.z); // driving -z
      // Ahead of the cameras at frame 0, level with them before frame 10.
      EXPECT_GT(start.z, 5.f);
      EXPECT_LT(meetingTime(m, config.speed_mps), 0.95);
    } else {
      ++ahead;
      EXPECT_NEAR(start.x, scene.layout.rightLaneX(), 0.15 + 1e-5); // the cameras' lane (x = 0)
      EXPECT_NEAR(scene.layout.rightLaneX(), 0.f, 1e-6);
      EXPECT_GE(start.z, 10.f);
      EXPECT_LE(start.z, 20.f);
      EXPECT_NEAR(m.speedMps(), config.speed_mps, 0.1 * config.speed_mps + 1e-6);
    }
  }
  EXPECT_EQ(ahead, 1);
  EXPECT_EQ(oncoming, 2);
  EXPECT_EQ(ids.size(), 3u);
  EXPECT_EQ(scene.objectCount(), static_objects + 3);
  // All of them are on the street at the first and last frame.
  EXPECT_EQ(SceneSnapshot(scene, 0.0).movers().size(), 3u);
  EXPECT_EQ(SceneSnapshot(scene, duration).movers().size(), 3u);
}

TEST(SyntheticTraffic, LongerDrivesMeetMoreOncomingCarsAndFollowTheCarAheadAllTheWay) {
  SyntheticConfig config;
  config.frames = 301; // 30 s, 300 m
  config.moving_cars_ahead = 2;
  const double duration = (config.frames - 1) / config.frame_rate_hz;
  const Scene scene = buildStreetScene(config, duration * config.speed_mps);
  std::vector<const MovingObject*> oncoming, ahead;
  for (const MovingObject& m : scene.movers)
    (isOncoming(m) ? oncoming : ahead).push_back(&m);
  // A group of 2 every 4 s: 8 groups in 30 s.
  EXPECT_EQ(oncoming.size(), 16u);
  ASSERT_EQ(ahead.size(), 2u);
  EXPECT_DOUBLE_EQ(ahead[0]->speedMps(), ahead[1]->speedMps()); // one platoon
  for (std::size_t k = 0; k < oncoming.size(); ++k) {
    const double t = meetingTime(*oncoming[k], config.speed_mps);
    EXPECT_LT(t, duration + config.oncoming_group_period_s) << "oncoming car " << k;
    if (k > 0) { // in the order met, at least 9 m apart (4.2 m between bumpers)
      const double gap = oncoming[k]->originAt(0.0).z - oncoming[k - 1]->originAt(0.0).z;
      EXPECT_GE(gap, 9.0 - 1e-3) << "oncoming car " << k;
    }
  }
  for (int i = 0; i < config.frames; i += 10) {
    const double t = i / config.frame_rate_hz;
    const double lead = ahead[0]->originAt(t).z - config.speed_mps * t;
    EXPECT_GE(lead, 8.0 - 1e-3) << "frame " << i;
    EXPECT_LE(lead, 40.0 + 1e-3) << "frame " << i;
    EXPECT_GT(ahead[1]->originAt(t).z - ahead[0]->originAt(t).z, 10.0 - 1e-3);
  }
  // The cars that are not yet (or no longer) on the street are left out of the snapshot.
  EXPECT_LT(SceneSnapshot(scene, 0.0).movers().size(), scene.movers.size());

  config.moving_cars_ahead = 0;
  config.moving_cars_oncoming = 0;
  EXPECT_TRUE(buildStreetScene(config, duration * config.speed_mps).movers.empty());
}

TEST(SyntheticTraffic, MoversComeFromTheirOwnStreamAndLeaveTheStaticStreetAsItWas) {
  SyntheticConfig config;
  config.frames = 20;
  SyntheticConfig off = config;
  off.moving_cars_ahead = 0;
  off.moving_cars_oncoming = 0;
  const Scene with = buildStreetScene(config, 19.0), again = buildStreetScene(config, 19.0);
  const Scene without = buildStreetScene(off, 19.0);
  ASSERT_EQ(with.primitives.size(), without.primitives.size());
  for (std::size_t i = 0; i < with.primitives.size(); ++i) {
    const Primitive &a = with.primitives[i], &b = without.primitives[i];
    ASSERT_TRUE(a.center.x == b.center.x && a.center.y == b.center.y && a.center.z == b.center.z &&
                a.half.x == b.half.x && a.half.y == b.half.y && a.half.z == b.half.z && a.cos_yaw == b.cos_yaw &&
                a.material == b.material && a.object == b.object)
        << "static solid " << i;
  }
  ASSERT_GT(with.materials.size(), without.materials.size()); // the movers' come after
  for (std::size_t i = 0; i < without.materials.size(); ++i)
    ASSERT_EQ(with.materials[i].seed, without.materials[i].seed) << "material " << i;

  // Deterministic in the seed; another seed, other cars.
  ASSERT_EQ(with.movers.size(), again.movers.size());
  for (std::size_t k = 0; k < with.movers.size(); ++k) {
    EXPECT_EQ(with.movers[k].originAt(0.7).z, again.movers[k].originAt(0.7).z);
    EXPECT_EQ(with.movers[k].solids()[0].half.z, again.movers[k].solids()[0].half.z);
  }
  config.seed = 8;
  const Scene other = buildStreetScene(config, 19.0);
  EXPECT_NE(other.movers[0].originAt(0.0).z, with.movers[0].originAt(0.0).z);
}

/// FNV-1a over raw bytes: a digest of rendered output.
std::uint64_t digest(const void* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<const unsigned char*>(data)[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

TEST(SyntheticTraffic, MoversOffRenderTheStaticStreetOfTheBuildBeforeThem) {
  // Digests of frame 0 of `msf_synth -frames 5` (seed 1) as written at 472dace, before
  // moving cars: image_0, obj_map_0 and the velodyne .bin. If the static street is changed
  // on purpose, these change with it.
  SyntheticConfig config;
  config.frames = 5;
  config.moving_cars_ahead = 0;
  config.moving_cars_oncoming = 0;
  const SyntheticFrame f = SyntheticGenerator(config).renderFrame(0, false);
  ASSERT_TRUE(f.images[0].isContinuous() && f.objects.isContinuous());
  EXPECT_EQ(digest(f.images[0].data, f.images[0].total()), 0xcf92167c7d51f7aeULL);
  EXPECT_EQ(digest(f.objects.data, f.objects.total()), 0xab3e30f303ac7fa7ULL);
  std::vector<float> scan;
  for (const auto& p : f.scan)
    scan.insert(scan.end(), {p.x, p.y, p.z, p.intensity});
  EXPECT_EQ(f.scan.size(), 118239u);
  EXPECT_EQ(digest(scan.data(), scan.size() * sizeof(float)), 0xe3edda4164a3d11fULL);
  EXPECT_EQ(cv::countNonZero(f.moving), 0);
}

/// Where a ray (t in units of `dir`) enters and leaves a box, and the local axis of the
/// entry face; false when it misses.
bool rayThroughBox(const MovingBox& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double& entry,
                   double& exit, int& entry_axis) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(box.yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d o = R.transpose() * (origin - box.center), d = R.transpose() * dir;
  entry = -1e300;
  exit = 1e300;
  for (int k = 0; k < 3; ++k) {
    const double a = (-box.half_extents[k] - o[k]) / d[k], b = (box.half_extents[k] - o[k]) / d[k];
    if (std::min(a, b) > entry) {
      entry = std::min(a, b);
      entry_axis = k;
    }
    exit = std::min(exit, std::max(a, b));
  }
  return entry <= exit && entry > 0.0;
}

std::vector<MovingBox> boxesAt(const std::vector<MovingBox>& boxes, std::size_t frame) {
  std::vector<MovingBox> out;
  for (const MovingBox& b : boxes)
    if (b.frame == frame)
      out.push_back(b);
  return out;
}

TEST(SyntheticMovers, CameraSeesEachMoverWhereItsBoxSaysAtTwoFrames) {
  auto& street = SharedStreet::instance();
  const SyntheticGenerator& gen = street.generator();
  const msf::Calibration& calib = gen.calibration();
  ASSERT_LT(gen.scene().objectCount(), 255u); // obj_map_0 holds the ids themselves
  const std::vector<MovingBox> boxes = gen.movingBoxes();
  std::map<std::uint32_t, std::map<std::size_t, double>> rear_z; // car ahead: its rear face's world z per frame
  int checked = 0;
  for (const std::size_t frame : {std::size_t{0}, std::size_t{5}}) {
    const SyntheticFrame& f = street.frame(frame);
    const Eigen::Isometry3d& T = gen.poses()[frame];
    const Eigen::Vector3d origin = T * calib.cameraCenter(0);
    for (const MovingBox& box : boxesAt(boxes, frame)) {
      int pixels = 0, on_entry_face = 0, rear_pixels = 0;
      double rear_sum = 0.0;
      for (int v = 0; v < f.depth.rows; ++v)
        for (int u = 0; u < f.depth.cols; ++u) {
          if (f.objects.at<std::uint8_t>(v, u) != box.object)
            continue;
          ++pixels;
          const Eigen::Vector3d dir =
              T.linear() * Eigen::Vector3d((u - calib.cx()) / calib.fx(), (v - calib.cy()) / calib.fy(), 1.0);
          double entry = 0.0, exit = 0.0;
          int axis = -1;
          ASSERT_TRUE(rayThroughBox(box, origin, dir, entry, exit, axis))
              << "frame " << frame << " object " << box.object << " pixel " << u << "," << v;
          const double z = f.depth.at<float>(v, u), tolerance = 1e-3 + 1e-5 * z;
          ASSERT_GE(z, entry - tolerance) << "frame " << frame << " pixel " << u << "," << v;
          ASSERT_LE(z, exit + tolerance) << "frame " << frame << " pixel " << u << "," << v;
          if (std::fabs(z - entry) > tolerance)
            continue;
          ++on_entry_face;
          if (axis == 2 && box.yaw == 0.0) { // the rear of a car driving +z
            ++rear_pixels;
            rear_sum += origin.z() + z * dir.z();
          }
        }
      if (pixels < 300)
        continue; // hardly in view
      ++checked;
      std::printf("frame %zu, moving object %u: %d pixels, %d on its box's entry face\n", frame, box.object, pixels,
                  on_entry_face);
      // The body's faces are the box's: much of a car is seen exactly on its box.
      EXPECT_GT(on_entry_face, pixels / 4) << "frame " << frame << " object " << box.object;
      if (rear_pixels > 100) {
        const double rear = rear_sum / rear_pixels;
        EXPECT_NEAR(rear, box.center.z() - box.half_extents.z(), 1e-3) << "frame " << frame;
        rear_z[box.object][frame] = rear;
      }
    }
  }
  EXPECT_GE(checked, 3);
  // The car ahead moved by its speed over the 5 frames between the two images.
  ASSERT_FALSE(rear_z.empty());
  for (const auto& [object, by_frame] : rear_z) {
    ASSERT_EQ(by_frame.size(), 2u) << "object " << object;
    const MovingObject* mover = nullptr;
    for (const MovingObject& m : gen.scene().movers)
      mover = m.object() == object ? &m : mover;
    ASSERT_NE(mover, nullptr);
    const double expected = mover->speedMps() * 5.0 / gen.config().frame_rate_hz;
    EXPECT_GT(expected, 4.0);
    EXPECT_NEAR(by_frame.at(5) - by_frame.at(0), expected, 2e-3) << "object " << object;
  }
}

TEST(SyntheticMovers, MovingMaskIsExactlyThePixelsOfMovingObjects) {
  auto& street = SharedStreet::instance();
  const SyntheticGenerator& gen = street.generator();
  ASSERT_LT(gen.scene().objectCount(), 255u);
  std::vector<std::uint8_t> is_moving(256, 0);
  for (const MovingObject& m : gen.scene().movers)
    is_moving[m.object()] = 255;
  for (const std::size_t frame : {std::size_t{0}, std::size_t{5}}) {
    const SyntheticFrame& f = street.frame(frame);
    ASSERT_EQ(f.moving.type(), CV_8UC1);
    ASSERT_EQ(f.moving.size(), f.objects.size());
    cv::Mat expected(f.objects.size(), CV_8UC1);
    for (int v = 0; v < expected.rows; ++v)
      for (int u = 0; u < expected.cols; ++u)
        expected.at<std::uint8_t>(v, u) = is_moving[f.objects.at<std::uint8_t>(v, u)];
    EXPECT_EQ(cv::countNonZero(f.moving != expected), 0) << "frame " << frame;
    EXPECT_GT(cv::countNonZero(f.moving), 2000) << "frame " << frame;
    // Static foreground (parked cars, poles, people) stays out of it.
    EXPECT_GT(cv::countNonZero((f.objects > 0) & (f.moving == 0)), 5000) << "frame " << frame;
  }
}

TEST(SyntheticMovers, LidarSeesTheCarAheadWhereItIsAtTheFramesTime) {
  auto& street = SharedStreet::instance();
  const SyntheticGenerator& gen = street.generator();
  const std::size_t frame = 5;
  const auto& scan = street.frame(frame).scan;
  const Eigen::Isometry3d T_world_velo = gen.poses()[frame] * gen.calibration().T_cam0_velo;
  const float ground_y = gen.scene().layout.ground_y;
  // The car ahead at frame 0 and at frame 5 (half a second later, about 5 m further).
  const MovingObject* ahead = nullptr;
  for (const MovingObject& m : gen.scene().movers)
    ahead = (!isOncoming(m) && !ahead) ? &m : ahead;
  ASSERT_NE(ahead, nullptr);
  const MovingBox then = ahead->boxAt(0.0), now = ahead->boxAt(frame / gen.config().frame_rate_hz);
  int in_now = 0, in_then = 0;
  for (const auto& p : scan) {
    const Eigen::Vector3d w = T_world_velo * Eigen::Vector3d(p.x, p.y, p.z);
    if (w.y() > ground_y - 0.15) // the road under the boxes
      continue;
    in_now += now.contains(w, 0.08) ? 1 : 0;
    in_then += then.contains(w, 0.08) && !now.contains(w, 0.08) ? 1 : 0;
  }
  std::printf("frame %zu: %d LiDAR returns on the car ahead, %d where it was at frame 0\n", frame, in_now, in_then);
  EXPECT_GT(in_now, 200);
  EXPECT_EQ(in_then, 0);
}

/// Triangles of `mesh` with a vertex, an edge midpoint or the centroid inside one of
/// `boxes` by more than 1 cm.
std::size_t trianglesInside(const pcl::PolygonMesh& mesh, const std::vector<MovingBox>& boxes) {
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(mesh.cloud, vertices);
  std::size_t inside = 0;
  for (const auto& polygon : mesh.polygons) {
    Eigen::Vector3d corner[3];
    for (int k = 0; k < 3; ++k)
      corner[k] = vertices[polygon.vertices[static_cast<std::size_t>(k)]].getVector3fMap().cast<double>();
    const Eigen::Vector3d samples[] = {corner[0],
                                       corner[1],
                                       corner[2],
                                       0.5 * (corner[0] + corner[1]),
                                       0.5 * (corner[1] + corner[2]),
                                       0.5 * (corner[2] + corner[0]),
                                       (corner[0] + corner[1] + corner[2]) / 3.0};
    bool any = false;
    for (const MovingBox& box : boxes)
      for (const Eigen::Vector3d& s : samples)
        any = any || box.contains(s, -0.01);
    inside += any ? 1 : 0;
  }
  return inside;
}

TEST(SyntheticMovers, SceneMeshHoldsNoTriangleInsideAnyMoverAtAnyFrame) {
  const SyntheticGenerator& gen = SharedStreet::instance().generator();
  const std::vector<MovingBox> boxes = gen.movingBoxes();
  ASSERT_EQ(boxes.size(), 3u * gen.size());
  const pcl::PolygonMesh mesh = gen.mesh();
  ASSERT_GT(mesh.polygons.size(), 10000u);
  EXPECT_EQ(trianglesInside(mesh, boxes), 0u);
  // The check finds a car where one is: the movers of frame 0 meshed as if they stood still.
  Scene parked;
  parked.layout = gen.scene().layout;
  parked.materials = gen.scene().materials;
  for (const MovingObject& m : gen.scene().movers)
    m.placeAt(0.0, parked.primitives);
  parked.buildIndex();
  EXPECT_GT(trianglesInside(sceneMesh(parked, gen.config().mesh_max_edge_m), boxesAt(boxes, 0)), 100u);
}

TEST(SyntheticMovingBoxes, ContainsIsTheOrientedBoxGrownByTheMargin) {
  MovingBox box;
  box.center = {1.0, 0.0, 10.0};
  box.half_extents = {1.0, 0.5, 2.0};
  box.yaw = M_PI / 2; // the front points along world +x: the 2 m half length lies along x
  EXPECT_TRUE(box.contains({2.9, 0.0, 10.0}));
  EXPECT_FALSE(box.contains({1.0, 0.0, 11.5}));
  EXPECT_TRUE(box.contains({1.0, 0.0, 10.95}));
  EXPECT_FALSE(box.contains({1.0, 0.6, 10.0}));
  EXPECT_TRUE(box.contains({1.0, 0.6, 10.0}, 0.2));   // grown
  EXPECT_FALSE(box.contains({2.9, 0.0, 10.0}, -0.2)); // shrunk
}

TEST(SyntheticMovingBoxes, FileRoundTripsThroughTheReader) {
  const std::vector<MovingBox> boxes = SharedStreet::instance().generator().movingBoxes();
  ASSERT_FALSE(boxes.empty());
  msf::test::TempDir dir;
  const std::string path = dir.file("moving_objects.txt");
  std::ofstream(path) << formatMovingBoxes(boxes);
  const std::vector<MovingBox> back = readMovingBoxes(path);
  ASSERT_EQ(back.size(), boxes.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    EXPECT_EQ(back[k].frame, boxes[k].frame);
    EXPECT_EQ(back[k].object, boxes[k].object);
    // What the renderer placed, to the float.
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(static_cast<float>(back[k].center[i]), static_cast<float>(boxes[k].center[i])) << "box " << k;
      EXPECT_EQ(static_cast<float>(back[k].half_extents[i]), static_cast<float>(boxes[k].half_extents[i]));
    }
    EXPECT_EQ(static_cast<float>(back[k].yaw), static_cast<float>(boxes[k].yaw));
  }
}

TEST(SyntheticMovingBoxes, AMissingOrGarbledFileIsAnIOErrorNamingFileAndLine) {
  msf::test::TempDir dir;
  const std::string path = dir.file("moving_objects.txt");
  try {
    readMovingBoxes(path);
    ADD_FAILURE() << "a missing file was read";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  const std::string good = "0 7 1 0.9 12 0.9 0.7 2.2 0\n";
  for (const char* bad :
       {"0 7 1 0.9 12 0.9 0.7 2.2\n", "0 7 1 0.9 12 0.9 0.7 2.2 0 5\n", "0 7 1 0.9 twelve 0.9 0.7 2.2 0\n",
        "-1 7 1 0.9 12 0.9 0.7 2.2 0\n", "0 7 1 0.9 12 -0.9 0.7 2.2 0\n", "0 7 1 0.9 12 0.9 0.7 2.2 nan\n",
        "0.5 7 1 0.9 12 0.9 0.7 2.2 0\n"}) {
    std::ofstream(path) << "# header\n" << good << "\n" << bad;
    try {
      readMovingBoxes(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const msf::IOError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find("line 4"), std::string::npos) << what;
    }
  }
  std::ofstream(path) << "# header\n" << good << "\n";
  EXPECT_EQ(readMovingBoxes(path).size(), 1u);
}

TEST(SyntheticMovingBoxes, GroundTruthWrittenBeforeMoversHasAnEmptyMaskAndNoBoxFile) {
  // The layout of a dataset written before moving cars: no moving_0/, no moving_objects.txt.
  msf::test::TempDir dir;
  const fs::path gt = fs::path(dir.path()) / "gt";
  fs::create_directories(gt / "depth_0");
  msf::writeKittiDepthPng((gt / "depth_0" / "000000.png").string(), cv::Mat(6, 8, CV_32F, cv::Scalar(5.f)));
  const GroundTruth truth(gt.string());
  const cv::Mat mask = truth.movingMask(0);
  EXPECT_EQ(mask.type(), CV_8UC1);
  EXPECT_EQ(mask.size(), cv::Size(8, 6));
  EXPECT_EQ(cv::countNonZero(mask), 0);
  try {
    truth.movingBoxes();
    ADD_FAILURE() << "a missing box file was read";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("moving_objects.txt"), std::string::npos) << e.what();
  }
  // Once moving_0/ exists, a missing frame is an error, not an empty mask.
  fs::create_directories(gt / "moving_0");
  EXPECT_THROW(truth.movingMask(0), msf::IOError);
}

} // namespace
