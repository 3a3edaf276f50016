// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A LiDAR's beams from a scan's per-point rings, for a rig that lists none (a ROS bag's).
#include <msf/io/beam_elevations.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

/// `count` returns of one beam at `elevation_deg`, spread in azimuth, 10 m away.
void addBeam(pcl::PointCloud<pcl::PointXYZI>& scan, std::vector<std::uint16_t>& rings, std::uint16_t ring,
             double elevation_deg, int count) {
  const double e = elevation_deg * M_PI / 180.0;
  for (int k = 0; k < count; ++k) {
    const double azimuth = 2.0 * M_PI * k / count;
    pcl::PointXYZI p;
    p.x = static_cast<float>(10.0 * std::cos(e) * std::cos(azimuth));
    p.y = static_cast<float>(10.0 * std::cos(e) * std::sin(azimuth));
    p.z = static_cast<float>(10.0 * std::sin(e));
    scan.push_back(p);
    rings.push_back(ring);
  }
}

TEST(BeamElevations, EachRingsMedianElevationLowestFirst) {
  // A 16-beam LiDAR from +15 to -15 degrees, its rings numbered from the top (as some drivers do).
  pcl::PointCloud<pcl::PointXYZI> scan;
  std::vector<std::uint16_t> rings;
  for (std::uint16_t ring = 0; ring < 16; ++ring)
    addBeam(scan, rings, ring, 15.0 - 2.0 * ring, 100);
  addBeam(scan, rings, 40, 30.0, 5); // a ring of a few returns: not a beam to count on
  const std::vector<double> beams = msf::beamElevationsFromRings(scan, rings);
  ASSERT_EQ(beams.size(), 16u);
  for (std::size_t b = 0; b < 16; ++b)
    EXPECT_NEAR(beams[b], -15.0 + 2.0 * static_cast<double>(b), 1e-4) << b;

  EXPECT_TRUE(msf::beamElevationsFromRings(scan, {}).empty()) << "a scan without rings lists no beams";
  pcl::PointCloud<pcl::PointXYZI> one;
  std::vector<std::uint16_t> one_ring;
  addBeam(one, one_ring, 3, -5.0, 100);
  EXPECT_TRUE(msf::beamElevationsFromRings(one, one_ring).empty()) << "one beam gives no spacing";

  // A beam missing between two others (ring 7 without returns): no beams, not a wider spacing.
  pcl::PointCloud<pcl::PointXYZI> gap;
  std::vector<std::uint16_t> gap_rings;
  for (std::uint16_t ring = 0; ring < 16; ++ring)
    addBeam(gap, gap_rings, ring, 15.0 - 2.0 * ring, ring == 7 ? 3 : 100);
  EXPECT_TRUE(msf::beamElevationsFromRings(gap, gap_rings).empty());
  // The top beam seeing only sky: the others, their spacing the same.
  pcl::PointCloud<pcl::PointXYZI> sky;
  std::vector<std::uint16_t> sky_rings;
  for (std::uint16_t ring = 0; ring < 16; ++ring)
    addBeam(sky, sky_rings, ring, 15.0 - 2.0 * ring, ring == 0 ? 2 : 100);
  const std::vector<double> below = msf::beamElevationsFromRings(sky, sky_rings);
  ASSERT_EQ(below.size(), 15u);
  EXPECT_NEAR(below.back(), 13.0, 1e-4);

  // A field named ring that numbers points round-robin, not beams: no beams.
  std::vector<std::uint16_t> round_robin(scan.size());
  for (std::size_t k = 0; k < scan.size(); ++k)
    round_robin[k] = static_cast<std::uint16_t>(k % 32);
  EXPECT_TRUE(msf::beamElevationsFromRings(scan, round_robin).empty());
}

} // namespace
