// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Ring ids by azimuth wraps (protocol 2) on hand-made sweeps and a real KITTI scan.
#include <msf/common/exceptions.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/ring_split.h>

#include <test_support.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace {

/// `rings` full sweeps of `steps` points, azimuth rising from -pi to pi, elevation by ring.
pcl::PointCloud<pcl::PointXYZI> sweeps(int rings, int steps) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (int r = 0; r < rings; ++r)
    for (int i = 0; i < steps; ++i) {
      const double a = -M_PI + (i + 0.5) * 2 * M_PI / steps;
      pcl::PointXYZI p;
      p.x = static_cast<float>(10 * std::cos(a));
      p.y = static_cast<float>(10 * std::sin(a));
      p.z = static_cast<float>(-0.1 * r);
      p.intensity = static_cast<float>(r);
      scan.push_back(p);
    }
  return scan;
}

TEST(RingSplit, IdsCountAzimuthWraps) {
  const auto scan = sweeps(6, 50);
  const std::vector<int> ids = msf::ringIds(scan);
  ASSERT_EQ(ids.size(), scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i)
    EXPECT_EQ(ids[i], static_cast<int>(scan[i].intensity)) << i;
}

// A 32-beam LiDAR (an HDL-32E's elevations) whose points come in no ring order: each point's
// ring is the beam nearest its elevation, and the split holds out the beams the ids say.
TEST(RingSplit, IdsFromBeamElevationsFollowThePointsNotTheirOrder) {
  std::vector<double> elevations;
  for (int b = 0; b < 32; ++b)
    elevations.push_back(-30.67 + b * (41.34 / 31));
  pcl::PointCloud<pcl::PointXYZI> scan;
  std::vector<int> beams;
  for (int k = 0; k < 640; ++k) {
    const int beam = (k * 7) % 32; // interleaved, as a sensor's packets are
    const double azimuth = 0.01 * k, range = 5.0 + k % 40;
    const double elevation = (elevations[beam] + 0.3 * ((k % 3) - 1) * (41.34 / 31) / 2) * M_PI / 180; // within half a gap
    pcl::PointXYZI p;
    p.x = static_cast<float>(range * std::cos(elevation) * std::cos(azimuth));
    p.y = static_cast<float>(range * std::cos(elevation) * std::sin(azimuth));
    p.z = static_cast<float>(range * std::sin(elevation));
    scan.push_back(p);
    beams.push_back(beam);
  }
  EXPECT_EQ(msf::ringIdsFromElevations(scan, elevations), beams);
  pcl::PointCloud<pcl::PointXYZI> input, heldout;
  EXPECT_EQ(msf::splitRings(scan, beams, msf::RingSplitConfig{}, input, heldout), 32);
  EXPECT_EQ(heldout.size(), 160u); // beams 2, 6, .., 30: 8 of 32
  EXPECT_EQ(input.size() + heldout.size(), scan.size());
  EXPECT_THROW(msf::ringIdsFromElevations(scan, {}), msf::InvalidInputError);
  EXPECT_THROW(msf::splitRings(scan, std::vector<int>(3, 0), msf::RingSplitConfig{}, input, heldout),
               msf::InvalidInputError);
}

TEST(RingSplit, HeldOutRingsAreIdModFourEqualTwoByDefault) {
  const auto scan = sweeps(8, 40);
  pcl::PointCloud<pcl::PointXYZI> input, heldout;
  EXPECT_EQ(msf::splitRings(scan, msf::RingSplitConfig(), input, heldout), 8);
  EXPECT_EQ(heldout.size(), 80u); // rings 2 and 6
  EXPECT_EQ(input.size(), 240u);
  for (const auto& p : heldout)
    EXPECT_TRUE(p.intensity == 2.f || p.intensity == 6.f);
  for (const auto& p : input)
    EXPECT_NE(static_cast<int>(p.intensity) % 4, 2);
  // File order is kept.
  for (std::size_t i = 1; i < input.size(); ++i)
    EXPECT_LE(input[i - 1].intensity, input[i].intensity);

  msf::RingSplitConfig every_other;
  every_other.modulo = 2;
  every_other.heldout_remainder = 1;
  msf::splitRings(scan, every_other, input, heldout);
  EXPECT_EQ(heldout.size(), 160u);
}

TEST(RingSplit, ConfigIsValidated) {
  msf::RingSplitConfig c;
  c.modulo = 1;
  EXPECT_THROW(c.validate(), msf::ConfigError);
  c.modulo = 4;
  c.heldout_remainder = 4;
  try {
    c.validate();
    FAIL();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("rings.heldout_remainder"), std::string::npos);
  }
  pcl::PointCloud<pcl::PointXYZI> a, b;
  EXPECT_THROW(msf::splitRings(sweeps(2, 4), c, a, b), msf::ConfigError);
}

TEST(RingSplit, RealKittiScanHas64Rings) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  pcl::PointCloud<pcl::PointXYZI> scan;
  msf::loadVelodyneBin(sequence.scanPath(0), scan);
  const std::vector<int> ids = msf::ringIds(scan);
  // 64 wraps. A KITTI laser's sweep starts and ends straight ahead, so the first and last
  // ids hold half a laser each and every id between holds one laser's full turn.
  EXPECT_EQ(ids.back(), 64);
  std::map<int, std::size_t> per_ring;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    ++per_ring[ids[i]];
    if (i > 0) {
      ASSERT_GE(ids[i], ids[i - 1]);
    }
  }
  EXPECT_EQ(per_ring.size(), 65u);
  for (int r = 1; r < 64; ++r)
    EXPECT_GT(per_ring[r], 1000u) << "ring " << r; // about 2000 azimuth steps a turn, fewer on sky
  // Elevation falls from ring to ring (the top laser first).
  auto elevation = [&](int ring) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < scan.size(); ++i)
      if (ids[i] == ring) {
        sum += std::atan2(scan[i].z, std::hypot(scan[i].x, scan[i].y));
        ++n;
      }
    return sum / static_cast<double>(n);
  };
  EXPECT_GT(elevation(5), elevation(30));
  EXPECT_GT(elevation(30), elevation(60));

  pcl::PointCloud<pcl::PointXYZI> input, heldout;
  EXPECT_EQ(msf::splitRings(scan, msf::RingSplitConfig(), input, heldout), 65);
  EXPECT_EQ(input.size() + heldout.size(), scan.size());
  const double share = static_cast<double>(heldout.size()) / static_cast<double>(scan.size());
  EXPECT_GT(share, 0.2);
  EXPECT_LT(share, 0.3);
}

} // namespace
