// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/registration/local_map.h>
#include <msf/registration/nearest_cache.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/registration/voxel_table.h>

#include <gtest/gtest.h>

#include <random>

namespace {

msf::PointList randomPoints(std::size_t n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent);
  msf::PointList points(n);
  for (auto& p : points)
    p = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return points;
}

TEST(VoxelTable, FindsWhatItHoldsThroughGrowth) {
  msf::VoxelTable table;
  EXPECT_EQ(table.find(5), msf::VoxelTable::kAbsent);
  for (int k = 0; k < 5000; ++k)
    EXPECT_TRUE(table.insert(msf::voxelKey(Eigen::Vector3i(k, -k, k % 7)), k).second);
  EXPECT_EQ(table.size(), 5000u);
  for (int k = 0; k < 5000; ++k)
    ASSERT_EQ(table.find(msf::voxelKey(Eigen::Vector3i(k, -k, k % 7))), k);
  const auto again = table.insert(msf::voxelKey(Eigen::Vector3i(3, -3, 3)), 99);
  EXPECT_FALSE(again.second);
  EXPECT_EQ(again.first, 3); // the first value stays
  EXPECT_EQ(table.find(msf::voxelKey(Eigen::Vector3i(3, 3, 3))), msf::VoxelTable::kAbsent);
  // Negative and positive coordinates of the same magnitude are different voxels.
  EXPECT_NE(msf::voxelKey(Eigen::Vector3i(-1, 0, 0)), msf::voxelKey(Eigen::Vector3i(1, 0, 0)));
  EXPECT_NE(msf::voxelKey(Eigen::Vector3i(0, -1, 0)), msf::voxelKey(Eigen::Vector3i(0, 0, -1)));
}

TEST(VoxelDownsample, KeepsTheFirstPointOfEachVoxelInOrder) {
  const msf::PointList points{{0.1, 0.1, 0.1}, {0.9, 0.2, 0.3}, {1.1, 0.1, 0.1}, {-0.1, 0.0, 0.0}, {1.5, 0.5, 0.5}};
  const msf::PointList kept = msf::voxelDownsample(points, 1.0);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[2]);
  EXPECT_EQ(kept[2], points[3]); // x = -0.1 is in voxel -1
  EXPECT_THROW(msf::voxelDownsample(points, 0.0), msf::InvalidInputError);
  // At most one point per voxel, and every voxel that had a point keeps one.
  const msf::PointList many = randomPoints(20000, 10.0, 1);
  const msf::PointList sparse = msf::voxelDownsample(many, 2.0);
  EXPECT_EQ(sparse.size(), 1000u); // 10 x 10 x 10 voxels of 2 m, all hit
}

TEST(LocalMap, NearestIsTheBruteForceNearestWithinReach) {
  msf::LocalMap map(1.0, 20);
  const msf::PointList points = randomPoints(3000, 5.0, 2);
  map.addPoints(points);
  const msf::PointList stored = map.points();
  EXPECT_EQ(stored.size(), map.size());
  EXPECT_LT(map.size(), points.size()); // spacing: not every point is kept
  const msf::PointList queries = randomPoints(500, 5.5, 3);
  msf::LocalMap::Neighbor n;
  for (const auto& q : queries) {
    double best = 1e9;
    for (const auto& p : stored)
      best = std::min(best, (p - q).squaredNorm());
    const bool found = map.nearest(q, 1.0, n);
    // Within one voxel's reach the search is exact; beyond max_distance nothing is returned.
    if (best < 1.0) {
      ASSERT_TRUE(found);
      EXPECT_DOUBLE_EQ(n.distance2, best);
      EXPECT_DOUBLE_EQ((n.point - q).squaredNorm(), best);
    } else {
      EXPECT_FALSE(found);
    }
  }
}

TEST(LocalMap, ClearanceIsTheSecondNearestWithinReach) {
  msf::LocalMap map(1.0, 20); // points 0.22 m apart and more are kept
  map.addPoints({{0.5, 0.5, 0.5}, {0.5, 0.5, 0.9}, {1.6, 0.5, 0.5}});
  ASSERT_EQ(map.size(), 3u);
  msf::LocalMap::Neighbor n;
  double clearance2 = 0.0;
  ASSERT_TRUE(map.nearest(Eigen::Vector3d(0.5, 0.5, 0.6), 2.0, n, &clearance2));
  EXPECT_NEAR(n.distance2, 0.01, 1e-12);
  EXPECT_NEAR(clearance2, 0.09, 1e-12);  // (0.5, 0.5, 0.9), not the farther point in the next voxel
  ASSERT_TRUE(map.nearest(Eigen::Vector3d(0.5, 0.5, 0.6), 0.2, n, &clearance2));
  EXPECT_NEAR(clearance2, 0.04, 1e-12);  // none other within 0.2 m
}

// The ICP's queries: points moved a little (and now and then a lot) between calls. Every
// answer must be the map's own; most must come without a search. A dense map with a short
// reach (most queries find a point) and a sparse one with a long reach (many find none, or
// have no map point around at all).
struct CacheCase {
  std::size_t map_points;
  double max_distance;
};
class NearestCacheTest : public ::testing::TestWithParam<CacheCase> {};

TEST_P(NearestCacheTest, AnswersAsTheMapDoesAndSearchesLess) {
  msf::LocalMap map(1.0, 10);
  map.addPoints(randomPoints(GetParam().map_points, 5.0, 4));
  const double max_distance = GetParam().max_distance;
  msf::PointList queries = randomPoints(400, 5.5, 5);
  msf::NearestCache cache(map, max_distance, queries.size());
  std::mt19937 rng(6);
  std::normal_distribution<double> small(0.0, 0.003);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t calls = 0, found = 0;
  for (int round = 0; round < 10; ++round) {
    for (std::size_t i = 0; i < queries.size(); ++i) {
      if (round > 0) {
        const double scale = unit(rng) < 0.05 ? 100.0 : 1.0; // a jump of ~0.3 m now and then
        queries[i] += scale * Eigen::Vector3d(small(rng), small(rng), small(rng));
      }
      msf::LocalMap::Neighbor expected, got;
      const bool in_reach = map.nearest(queries[i], max_distance, expected);
      ASSERT_EQ(cache.nearest(i, queries[i], got), in_reach) << "query " << i << " round " << round;
      ++calls;
      if (!in_reach)
        continue;
      ++found;
      ASSERT_EQ(got.point, expected.point) << "query " << i << " round " << round;
      EXPECT_DOUBLE_EQ(got.distance2, expected.distance2);
      EXPECT_EQ(got.planar, expected.planar);
    }
  }
  EXPECT_GT(found, calls / 10); // both cases, found and not, are exercised
  EXPECT_LT(found, calls);
  EXPECT_GE(cache.searches(), queries.size()); // each searched once at least
  EXPECT_LT(cache.searches(), calls / 4);
}

INSTANTIATE_TEST_SUITE_P(DenseAndSparse, NearestCacheTest,
                         ::testing::Values(CacheCase{4000, 0.8}, CacheCase{150, 2.0}));

TEST(LocalMap, SpreadsPointsOverAVoxelAndFitsItsPlane) {
  msf::LocalMap map(1.0, 16);
  msf::PointList road;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      road.emplace_back(0.025 * i, 0.025 * j, 0.3 + 0.001 * ((i * 7 + j * 3) % 5)); // 1 mm of roughness
  map.addPoints(road);
  EXPECT_EQ(map.voxelCount(), 1u);
  // 1/sqrt(16) = 0.25 m apart at least: 16 points fit on the 1 m square, no more.
  EXPECT_LE(map.size(), 16u);
  EXPECT_GE(map.size(), 9u);
  msf::LocalMap::Neighbor n;
  ASSERT_TRUE(map.nearest(Eigen::Vector3d(0.5, 0.5, 0.8), 1.0, n));
  EXPECT_TRUE(n.planar);
  EXPECT_NEAR(std::abs(n.normal.z()), 1.0, 1e-3);
  // The same points again change nothing: the spacing rejects them.
  map.addPoints(road);
  EXPECT_LE(map.size(), 16u);

  // An edge (a kerb: the road and a face across it in one voxel) is not a plane.
  msf::LocalMap edge(1.0, 20);
  msf::PointList kerb;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      kerb.emplace_back(2.05 + 0.1 * i, 0.05 + 0.2 * j, 0.05);      // road
      kerb.emplace_back(2.6, 0.05 + 0.2 * j, 0.15 + 0.2 * i);        // face
    }
  edge.addPoints(kerb);
  ASSERT_TRUE(edge.nearest(Eigen::Vector3d(2.5, 0.5, 0.3), 1.0, n));
  EXPECT_FALSE(n.planar);
}

TEST(LocalMap, DropsVoxelsFarFromTheSensor) {
  msf::LocalMap map(1.0, 5);
  map.addPoints({{0.5, 0.5, 0.5}, {10.5, 0.5, 0.5}, {50.5, 0.5, 0.5}, {-50.5, 0.5, 0.5}});
  EXPECT_EQ(map.voxelCount(), 4u);
  map.removeFarFrom(Eigen::Vector3d(5, 0, 0), 20.0);
  EXPECT_EQ(map.voxelCount(), 2u);
  EXPECT_EQ(map.size(), 2u);
  msf::LocalMap::Neighbor n;
  EXPECT_TRUE(map.nearest(Eigen::Vector3d(10.4, 0.5, 0.5), 1.0, n)); // the table was rebuilt
  EXPECT_FALSE(map.nearest(Eigen::Vector3d(50.5, 0.5, 0.5), 1.0, n));
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_THROW(msf::LocalMap(0.0, 5), msf::InvalidInputError);
  EXPECT_THROW(msf::LocalMap(1.0, 0), msf::InvalidInputError);
}

} // namespace
