// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Geometry, hierarchy, textures and random numbers of the generator, on known answers.
#include "synthetic_fixture.h"

#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/primitive.h>
#include <msf/synthetic/procedural_noise.h>
#include <msf/synthetic/scene.h>
#include <msf/synthetic/street_scene.h>
#include <msf/synthetic/trajectory.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using namespace msf::synthetic;

Primitive makeBox(V3 center, V3 half, float yaw = 0.f) {
  Primitive p;
  p.shape = Shape::Box;
  p.center = center;
  p.half = half;
  p.setYaw(yaw);
  return p;
}

/// The road plane's hit within 1000 m (or none), where testing every solid in turn starts.
Hit roadPlane(const Scene& scene, const Ray& ray) {
  Hit hit;
  hit.t = 1000.f;
  if (ray.dir.y > 0.f) {
    const float t = (scene.layout.ground_y - ray.origin.y) / ray.dir.y;
    if (t > 0.f && t < hit.t) {
      hit.t = t;
      hit.primitive = Hit::kGround;
    }
  }
  return hit;
}

TEST(SyntheticGeometry, BoxHitFaceNormalAndLocalPoint) {
  const Primitive box = makeBox({0.f, 0.f, 10.f}, {1.f, 2.f, 3.f});
  Hit hit;
  ASSERT_TRUE(box.intersect({{0.5f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, hit));
  EXPECT_FLOAT_EQ(hit.t, 7.f);
  EXPECT_EQ(hit.face, 5); // entered through -z
  EXPECT_FLOAT_EQ(hit.normal.z, -1.f);
  EXPECT_FLOAT_EQ(hit.local.x, 0.5f);
  EXPECT_FLOAT_EQ(hit.local.z, -3.f);
  // Missing it, and starting inside it, find nothing.
  Hit miss;
  EXPECT_FALSE(box.intersect({{1.5f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, miss));
  EXPECT_FALSE(box.intersect({{0.f, 0.f, 10.f}, {0.f, 0.f, 1.f}}, 0.f, miss));
  // A closer hit already found wins.
  Hit closer;
  closer.t = 5.f;
  EXPECT_FALSE(box.intersect({{0.5f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, closer));
}

TEST(SyntheticGeometry, RotatedBoxIsHitAtItsRotatedFace) {
  // Rotated by 90 degrees about y: the local x half extent (1) now lies along world z.
  const Primitive box = makeBox({0.f, 0.f, 10.f}, {1.f, 2.f, 3.f}, static_cast<float>(M_PI / 2));
  Hit hit;
  ASSERT_TRUE(box.intersect({{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, hit));
  EXPECT_NEAR(hit.t, 9.f, 1e-5);
  EXPECT_NEAR(hit.normal.z, -1.f, 1e-6);
  V3 lo, hi;
  box.bounds(lo, hi);
  EXPECT_NEAR(lo.x, -3.f, 1e-5);
  EXPECT_NEAR(hi.z, 11.f, 1e-5);
}

TEST(SyntheticGeometry, CylinderSideAndCap) {
  Primitive c;
  c.shape = Shape::Cylinder;
  c.axis = 1; // vertical
  c.center = {0.f, 0.f, 5.f};
  c.half = {0.5f, 2.f, 0.5f};
  Hit side;
  ASSERT_TRUE(c.intersect({{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, side));
  EXPECT_FLOAT_EQ(side.t, 4.5f);
  EXPECT_EQ(side.face, 0);
  EXPECT_NEAR(side.normal.z, -1.f, 1e-6);
  Hit cap; // from above (y down: above is -y), straight down
  ASSERT_TRUE(c.intersect({{0.2f, -10.f, 5.f}, {0.f, 1.f, 0.f}}, 0.f, cap));
  EXPECT_FLOAT_EQ(cap.t, 8.f);
  EXPECT_EQ(cap.face, 2);
  EXPECT_FLOAT_EQ(cap.normal.y, -1.f);
  Hit miss;
  EXPECT_FALSE(c.intersect({{0.6f, -10.f, 5.f}, {0.f, 1.f, 0.f}}, 0.f, miss));
  EXPECT_TRUE(c.contains({0.f, 1.9f, 5.f}, 0.f));
  EXPECT_FALSE(c.contains({0.f, 2.1f, 5.f}, 0.f));
}

TEST(SyntheticGeometry, EllipsoidHitAndNormal) {
  Primitive e;
  e.shape = Shape::Ellipsoid;
  e.center = {0.f, 0.f, 10.f};
  e.half = {1.f, 2.f, 4.f};
  Hit hit;
  ASSERT_TRUE(e.intersect({{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, hit));
  EXPECT_FLOAT_EQ(hit.t, 6.f);
  EXPECT_NEAR(hit.normal.z, -1.f, 1e-6);
  Hit top;
  ASSERT_TRUE(e.intersect({{0.f, -10.f, 10.f}, {0.f, 1.f, 0.f}}, 0.f, top));
  EXPECT_FLOAT_EQ(top.t, 8.f);
}

TEST(SyntheticScene, HierarchyFindsTheSameHitsAsTestingEverySolid) {
  SyntheticConfig config;
  config.frames = 20;
  config.seed = 3;
  const Scene scene = buildStreetScene(config, 19.0);
  ASSERT_GT(scene.primitives.size(), 300u);
  SequentialRng rng(99);
  int agreed = 0;
  for (int n = 0; n < 3000; ++n) {
    const Ray ray{{static_cast<float>(rng.uniform(-3, 3)), static_cast<float>(rng.uniform(-1, 1)),
                   static_cast<float>(rng.uniform(-20, 40))},
                  normalized({static_cast<float>(rng.uniform(-1, 1)), static_cast<float>(rng.uniform(-0.5, 0.5)),
                              static_cast<float>(rng.uniform(-1, 1))})};
    Hit fast;
    const bool found = scene.intersect(ray, 0.f, 1000.f, fast);
    Hit brute = roadPlane(scene, ray);
    for (std::size_t i = 0; i < scene.primitives.size(); ++i)
      if (scene.primitives[i].intersect(ray, 0.f, brute))
        brute.primitive = static_cast<int>(i);
    ASSERT_EQ(found, brute.primitive != -1) << "ray " << n;
    if (found) {
      ASSERT_FLOAT_EQ(fast.t, brute.t) << "ray " << n;
      ASSERT_EQ(fast.primitive, brute.primitive) << "ray " << n;
      ++agreed;
    }
  }
  EXPECT_GT(agreed, 2500); // the street is enclosed: almost every ray hits something
}

TEST(SyntheticScene, SolidsAtTheSameDistanceGiveOneOfThemTheSameEveryTime) {
  // Boxes on a grid, and copies of some of them (the same floats, so every ray meeting one
  // meets its copy at exactly the same t) before and after the original: the hit is at the
  // distance testing every solid gives, on one of the solids there, the same one every time
  // (the hierarchy's order; SyntheticRendering pins which, on the street).
  Scene scene;
  std::vector<Primitive> grid;
  for (int i = 0; i < 60; ++i)
    grid.push_back(makeBox({static_cast<float>(i % 6) * 3.f - 7.5f, -1.f, static_cast<float>(i / 6) * 4.f + 5.f},
                           {0.6f + 0.05f * static_cast<float>(i % 5), 0.8f, 0.7f}, 0.3f * static_cast<float>(i % 3)));
  const std::vector<int> copied = {7, 23, 41, 7, 50, 12};
  for (std::size_t k = 0; k < 3; ++k)
    scene.add(grid[static_cast<std::size_t>(copied[k])]); // indices 0-2
  for (const Primitive& p : grid)
    scene.add(p); // indices 3-62: grid[i] is index i + 3
  for (std::size_t k = 3; k < copied.size(); ++k)
    scene.add(grid[static_cast<std::size_t>(copied[k])]); // indices 63-65
  scene.buildIndex();
  SequentialRng rng(17);
  int ties = 0;
  for (int n = 0; n < 4000; ++n) {
    const Ray ray{{static_cast<float>(rng.uniform(-12, 12)), static_cast<float>(rng.uniform(-4, 0)),
                   static_cast<float>(rng.uniform(-5, 0))},
                  normalized({static_cast<float>(rng.uniform(-0.6, 0.6)), static_cast<float>(rng.uniform(-0.1, 0.2)),
                              1.f})};
    Hit fast, again;
    const bool found = scene.intersect(ray, 0.f, 1000.f, fast);
    scene.intersect(ray, 0.f, 1000.f, again);
    Hit brute = roadPlane(scene, ray);
    std::vector<int> at_t; // every solid hit at brute.t
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
      Hit h;
      if (scene.primitives[i].intersect(ray, 0.f, h) && h.t <= brute.t) {
        if (h.t < brute.t)
          at_t.clear();
        brute.t = h.t;
        brute.primitive = static_cast<int>(i);
        at_t.push_back(static_cast<int>(i));
      }
    }
    ASSERT_EQ(found, brute.primitive != -1) << "ray " << n;
    ASSERT_EQ(fast.t, brute.t) << "ray " << n;
    ASSERT_EQ(fast.primitive, again.primitive) << "ray " << n;
    if (brute.primitive == Hit::kGround || !found)
      continue;
    ASSERT_NE(std::find(at_t.begin(), at_t.end(), fast.primitive), at_t.end()) << "ray " << n;
    ties += at_t.size() > 1 ? 1 : 0;
  }
  EXPECT_GT(ties, 50); // 93 of the 4000 rays

}

TEST(SyntheticScene, StreetHasEveryKindOfObjectAndIsDeterministic) {
  SyntheticConfig config;
  config.frames = 10;
  const Scene a = buildStreetScene(config, 9.0), b = buildStreetScene(config, 9.0);
  ASSERT_EQ(a.primitives.size(), b.primitives.size());
  for (std::size_t i = 0; i < a.primitives.size(); ++i) {
    ASSERT_EQ(a.primitives[i].center.x, b.primitives[i].center.x);
    ASSERT_EQ(a.primitives[i].half.z, b.primitives[i].half.z);
  }
  std::map<MaterialType, int> kinds;
  for (const auto& p : a.primitives)
    ++kinds[a.materials[p.material].type];
  for (const MaterialType t : {MaterialType::Sidewalk, MaterialType::Plaster, MaterialType::Brick,
                               MaterialType::BlankWall, MaterialType::CarPaint, MaterialType::CarCabin,
                               MaterialType::Tyre, MaterialType::Metal, MaterialType::Bark, MaterialType::Foliage,
                               MaterialType::Cloth, MaterialType::Skin})
    EXPECT_GT(kinds[t], 0) << "material type " << static_cast<int>(t);
  EXPECT_GT(a.objectCount(), 20u);
  config.seed = 2;
  const Scene c = buildStreetScene(config, 9.0);
  EXPECT_NE(c.primitives.size() == a.primitives.size() && c.primitives[200].center.z == a.primitives[200].center.z,
            true);
  // The ego lane is free: nothing stands on the road ahead of the cameras.
  Hit hit;
  ASSERT_TRUE(a.intersect({{0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}}, 0.f, 1000.f, hit));
  EXPECT_GT(hit.t, 100.f);
  EXPECT_TRUE(a.occupied({0.f, 1.7f, 0.f}, 0.f));  // below the road
  EXPECT_FALSE(a.occupied({0.f, 1.6f, 0.f}, 0.f)); // above it
}

TEST(SyntheticTrajectory, DrivesTenMetresASecondFromTheWorldOrigin) {
  SyntheticConfig config;
  config.frames = 101;
  const msf::PoseList poses = streetTrajectory(config);
  ASSERT_EQ(poses.size(), 101u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12)); // the world is camera 0 at frame 0
  EXPECT_NEAR(poses[1].translation().z(), 1.0, 1e-9);                  // 10 m/s at 10 Hz
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Eigen::Vector3d step = poses[i].translation() - poses[i - 1].translation();
    EXPECT_NEAR(step.norm(), 1.0, 0.002);
    EXPECT_NEAR(poses[i].translation().y(), 0.0, 1e-12); // constant height over the flat road
    // The heading follows the path, turning about the vertical axis only.
    const Eigen::Vector3d forward = poses[i].linear() * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(forward.y(), 0.0, 1e-12);
    EXPECT_NEAR(std::atan2(forward.x(), forward.z()), std::atan2(step.x(), step.z()), 0.002);
    EXPECT_LE(std::fabs(poses[i].translation().x()), 0.8 + 1e-9); // stays in its lane
  }
  const auto times = frameTimes(config);
  EXPECT_DOUBLE_EQ(times[0], 0.0);
  EXPECT_DOUBLE_EQ(times[10], 1.0);
}

TEST(SyntheticTrajectory, ALoopTurnsRoundAndDrivesBackInTheOtherLaneClearOfTheCars) {
  SyntheticConfig config;
  config.frames = 200;
  config.loop = true;
  const msf::PoseList poses = streetTrajectory(config);
  ASSERT_EQ(poses.size(), 200u);
  const int out = loopOutFrames(config);
  EXPECT_EQ(out, 95);
  EXPECT_NEAR(poses[out - 1].translation().z(), 94.0, 0.01);
  // Back where it began, a lane to the left, facing the other way.
  const Eigen::Vector3d end = poses.back().translation();
  EXPECT_NEAR(end.z(), poses[out - 1].translation().z() - 94.0, 0.01);
  EXPECT_NEAR(end.x() - poses[out - 1].translation().x(), -StreetLayout().lane_width_m, 1e-6);
  EXPECT_NEAR((poses.back().linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1e-9);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Eigen::Vector3d step = poses[i].translation() - poses[i - 1].translation();
    EXPECT_LT(step.norm(), 1.01) << i;
    // Forward is along the step (the turn's steps are chords of its arc).
    const Eigen::Vector3d forward = poses[i].linear() * Eigen::Vector3d::UnitZ();
    EXPECT_GT(forward.dot(step.normalized()), 0.95) << i;
  }
  // No moving car ever covers the cameras, on the way out, in the turn or back.
  const Scene scene = buildStreetScene(config, 100.0);
  ASSERT_FALSE(scene.movers.empty());
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (const auto& mover : scene.movers)
      EXPECT_FALSE(mover.boxAt(static_cast<double>(i) / config.frame_rate_hz).contains(poses[i].translation(), 1.0))
          << "frame " << i;
}

TEST(SyntheticTextures, PulseCoverageIsTheExactBoxFilter) {
  // Pulses [0, 0.25) of period 1: a box of width 0.5 centred at 0 covers [-0.25, 0.25).
  EXPECT_NEAR(pulseCoverage(0.0, 1.0, 0.25, 0.5), 0.5, 1e-9);
  EXPECT_NEAR(pulseCoverage(0.125, 1.0, 0.25, 0.0), 1.0, 1e-9);
  EXPECT_NEAR(pulseCoverage(0.5, 1.0, 0.25, 0.0), 0.0, 1e-9);
  EXPECT_NEAR(pulseCoverage(7.3, 1.0, 0.25, 10.0), 0.25, 1e-6); // wide boxes see the duty cycle
  EXPECT_NEAR(intervalCoverage(1.0, 0.0, 1.0, 1.0), 0.5, 1e-9);
  EXPECT_NEAR(intervalCoverage(3.0, 0.0, 1.0, 1.0), 0.0, 1e-9);
}

TEST(SyntheticTextures, NoiseIsBoundedAndFadesWithTheFootprint) {
  double sum = 0, sum2 = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const float x = 0.37f * i, y = 0.11f * i;
    const float v = fbm(x, y, 5u, 1.f, 6, 1e-4f);
    ASSERT_GE(v, -1.f);
    ASSERT_LE(v, 1.f);
    sum += v;
    sum2 += v * v;
    // A footprint larger than every wavelength averages the pattern away.
    ASSERT_EQ(fbm(x, y, 5u, 1.f, 6, 10.f), 0.f);
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_GT(sd, 0.15);
  EXPECT_EQ(valueNoise(1.25f, 2.5f, 9u), valueNoise(1.25f, 2.5f, 9u));
  EXPECT_NE(valueNoise(1.25f, 2.5f, 9u), valueNoise(1.25f, 2.5f, 10u));
}

TEST(SyntheticRandom, CounterHashesGiveStandardNormals) {
  double sum = 0, sum2 = 0, fast_sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double g = gaussian(hashKey(1, 2, 3, static_cast<std::uint64_t>(i)));
    sum += g;
    sum2 += g * g;
    const double f = gaussianFast(hashKey(4, static_cast<std::uint64_t>(i)));
    fast_sum2 += f * f;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.02);
  EXPECT_NEAR(fast_sum2 / n, 1.0, 0.02);
  EXPECT_EQ(hashKey(1, 2, 3), hashKey(1, 2, 3));
  EXPECT_NE(hashKey(1, 2, 3), hashKey(1, 3, 2));
  // The values datasets were made with (a seed gives the same files as before).
  EXPECT_EQ(hashKey(1, 2, 3, 4, 5), 0x0d3c90b0c030a276ULL);
  EXPECT_EQ(hashKey(7), 0xb06b4a62b750107bULL);
  // A prefix hashed once, the rest per key: the same values.
  const HashPrefix image = HashPrefix(1).then(20).then(0);
  EXPECT_EQ(image.then(466000).then(2).value(), 0x3fd146a03a28c2f1ULL);
  EXPECT_EQ(image.then(466000).value(), hashKey(1, 20, 0, 466000));
  SequentialRng a(5), b(5);
  for (int i = 0; i < 10; ++i)
    EXPECT_EQ(a.next(), b.next());
}

} // namespace
