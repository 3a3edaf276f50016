// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The shared grid helpers: the spatial hash, the grid keys and the stages' clock.
#include <msf/common/elapsed.h>
#include <msf/common/grid_key.h>
#include <msf/common/spatial_hash.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <tuple>
#include <vector>

namespace {

using msf::GridKey;
using msf::spatialHash;
using msf::spatialHash32;

TEST(SpatialHash, KnownValues) {
  EXPECT_EQ(spatialHash(1, 0, 0), 73856093u);
  EXPECT_EQ(spatialHash(0, 1, 0), 19349663u);
  EXPECT_EQ(spatialHash(0, 0, 1), 83492791u);
  EXPECT_EQ(spatialHash(1, 1, 1), 28855157u); // 73856093 ^ 19349663 ^ 83492791
  // A negative coordinate is sign-extended, the bits of a float (an unsigned 32-bit value) are not.
  EXPECT_EQ(spatialHash(-1, 0, 0), 18446744073635695523ull);
  EXPECT_EQ(spatialHash(std::uint32_t{0xffffffffu}, 0, 0), 317209503971478435ull);
  EXPECT_EQ(msf::CellHash()(Eigen::Vector3i(1, 1, 1)), 28855157u);
}

TEST(SpatialHash, ThirtyTwoBitsAreTheLowBitsOfSixtyFour) {
  for (const auto& [x, y, z] : std::vector<std::tuple<int, int, int>>{
           {0, 0, 0}, {1, -1, 7}, {-524288, 524287, 3}, {123456, -654321, -99}, {2147483647, -2147483647 - 1, 1}})
    EXPECT_EQ(spatialHash32(x, y, z), static_cast<std::uint32_t>(spatialHash(x, y, z))) << x << " " << y << " " << z;
}

TEST(GridKey, RoundTripsOverItsRangeAndSortsAsTheCoordinates) {
  using Key = GridKey<20>;
  const int lo = -(1 << 19), hi = (1 << 19) - 1;
  std::vector<Eigen::Vector3i> cells;
  for (const int x : {lo, -1, 0, 1, hi})
    for (const int y : {lo, 0, hi})
      for (const int z : {lo, -5, 0, hi})
        cells.emplace_back(x, y, z);
  std::vector<std::uint64_t> keys;
  for (const Eigen::Vector3i& c : cells) {
    EXPECT_EQ(Key::unpack(Key::pack(c)), c);
    EXPECT_LT(Key::pack(c), std::uint64_t(1) << 60); // 3 bits free for a sub-block
    keys.push_back(Key::pack(c));
  }
  // cells is in lexicographic order already: so are their keys.
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end());
}

TEST(GridKey, OutsideItsRangeACoordinateAliases) {
  using Key = GridKey<20>;
  EXPECT_EQ(Key::pack({1 << 19, 0, 0}), Key::pack({-(1 << 19), 0, 0}));
  EXPECT_EQ(Key::unpack(Key::pack({0, 0, (1 << 20) + 3})), Eigen::Vector3i(0, 0, 3));
}

TEST(GridKey, TwentyOneBitsIsTheBlockAndTileKeyLayout) {
  // x + 2^20 in bits 42.., y + 2^20 in bits 21.., z + 2^20 in bits 0..: the keys the stores
  // and the mesher have always used.
  const Eigen::Vector3i c(-3, 1000, -(1 << 20));
  const std::int64_t bias = 1 << 20;
  EXPECT_EQ(GridKey<21>::pack(c), (static_cast<std::uint64_t>(c.x() + bias) << 42) |
                                      (static_cast<std::uint64_t>(c.y() + bias) << 21) |
                                      static_cast<std::uint64_t>(c.z() + bias));
  EXPECT_EQ(GridKey<21>::unpack(GridKey<21>::pack(c)), c);
}

TEST(Elapsed, MillisecondsSinceAPointInThePast) {
  const double ms = msf::msSince(std::chrono::steady_clock::now() - std::chrono::milliseconds(50));
  EXPECT_GE(ms, 50.0);
  EXPECT_LT(ms, 60000.0);
}

} // namespace
