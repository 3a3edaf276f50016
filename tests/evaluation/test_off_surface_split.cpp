// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The mesh's area off the true surface, split by height above the ground and the LiDAR's support.
#include <msf/common/exceptions.h>
#include <msf/evaluation/off_surface_split.h>

#include "test_support.h"

#include <pcl/conversions.h>
#include <pcl/point_types.h>

namespace {

/// The true surface: the ground, a 20 m square in the plane z = 0 (z up).
msf::SurfaceDistance ground() {
  return msf::SurfaceDistance({{-10.f, -10.f, 0.f}, {10.f, -10.f, 0.f}, {10.f, 10.f, 0.f}, {-10.f, 10.f, 0.f}},
                              {{{0, 1, 2}}, {{0, 2, 3}}});
}

/// Adds a level right triangle with legs `leg` (area leg^2 / 2) whose centroid is `centroid`.
void addTriangle(msf::TriangleMesh& mesh, const Eigen::Vector3f& centroid, float leg) {
  const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
  const Eigen::Vector3f corner = centroid - Eigen::Vector3f(leg / 3.f, leg / 3.f, 0.f);
  mesh.vertices.push_back(corner);
  mesh.vertices.push_back(corner + Eigen::Vector3f(leg, 0.f, 0.f));
  mesh.vertices.push_back(corner + Eigen::Vector3f(0.f, leg, 0.f));
  mesh.triangles.push_back({first, first + 1, first + 2});
}

const Eigen::Hyperplane<float, 3> kGround(Eigen::Vector3f::UnitZ(), 0.f);

} // namespace

TEST(OffSurfaceSplit, SharesOfTheAreaOffTheSurfaceByHeightAndLidarSupport) {
  msf::TriangleMesh mesh;
  addTriangle(mesh, {0.f, 0.f, 0.05f}, 1.f);  // on the ground (5 cm): not off, 0.5 m2
  addTriangle(mesh, {2.f, 0.f, 1.f}, 1.f);    // 1 m up, a return beside it: 0.5 m2
  addTriangle(mesh, {4.f, 0.f, 3.f}, 2.f);    // 3 m up, none: 2 m2
  addTriangle(mesh, {6.f, 0.f, 7.f}, std::sqrt(2.f)); // 7 m up, none: 1 m2
  addTriangle(mesh, {8.f, 0.f, 7.f}, 1.f);    // 7 m up, a return beside it: 0.5 m2
  msf::LidarSupport support(0.1);
  support.addPoint({2.05f, 0.f, 1.f});
  support.addPoint({8.f, 0.05f, 7.05f});
  support.addPoint({4.f, 0.f, 3.5f}); // five cells above the 3 m triangle: too far to support it
  const msf::OffSurfaceSplit split = msf::splitOffSurface(mesh, ground(), kGround, support, 0.2, {2.0, 5.0});
  EXPECT_DOUBLE_EQ(split.distance_m, 0.2);
  EXPECT_NEAR(split.area_m2, 4.5, 1e-5);
  EXPECT_NEAR(split.off_area_m2, 4.0, 1e-5);
  EXPECT_NEAR(split.offShare(), 4.0 / 4.5, 1e-6);
  ASSERT_EQ(split.bands.size(), 3u);
  EXPECT_EQ(split.bands[0].upper_m, 2.0);
  EXPECT_EQ(split.bands[1].lower_m, 2.0);
  EXPECT_EQ(split.bands[2].lower_m, 5.0);
  const double expected[3][2] = {{0.125, 0.0}, {0.0, 0.5}, {0.125, 0.25}}; // {supported, none} per band
  for (std::size_t b = 0; b < 3; ++b) {
    EXPECT_NEAR(split.shareOfOff(split.bands[b].supported_m2), expected[b][0], 1e-6) << "band " << b;
    EXPECT_NEAR(split.shareOfOff(split.bands[b].unsupported_m2), expected[b][1], 1e-6) << "band " << b;
  }
}

TEST(OffSurfaceSplit, AMeshOnTheSurfaceHasNothingOff) {
  msf::TriangleMesh mesh;
  addTriangle(mesh, {1.f, 1.f, 0.1f}, 1.f);
  const msf::OffSurfaceSplit split = msf::splitOffSurface(mesh, ground(), kGround, msf::LidarSupport(0.1), 0.2, {2.0});
  EXPECT_NEAR(split.area_m2, 0.5, 1e-6);
  EXPECT_EQ(split.off_area_m2, 0.0);
  EXPECT_EQ(split.shareOfOff(0.0), 0.0);
}

TEST(OffSurfaceSplit, RefusesABadDistanceEdgesAndIndices) {
  msf::TriangleMesh mesh;
  addTriangle(mesh, {1.f, 1.f, 3.f}, 1.f);
  const msf::LidarSupport support(0.1);
  EXPECT_NE(msf::test::errorOf([&] { msf::splitOffSurface(mesh, ground(), kGround, support, 0.0, {2.0}); })
                .find("distance must be > 0"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([&] { msf::splitOffSurface(mesh, ground(), kGround, support, 0.2, {5.0, 2.0}); })
                .find("band edges must be finite and rise"),
            std::string::npos);
  mesh.triangles.push_back({0, 1, 7});
  EXPECT_NE(msf::test::errorOf([&] { msf::splitOffSurface(mesh, ground(), kGround, support, 0.2, {2.0}); })
                .find("beyond the mesh's 3 vertices"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([] { msf::LidarSupport bad(0.0); }).find("cell must be > 0"), std::string::npos);
}

TEST(LidarSupport, AReturnSupportsItsCellAndTheNeighbours) {
  msf::LidarSupport support(0.5);
  pcl::PointCloud<pcl::PointXYZI> scan;
  pcl::PointXYZI p;
  p.x = 1.2f, p.y = 0.2f, p.z = 0.2f; // the LiDAR's frame, moved 10 m along world x below
  scan.push_back(p);
  p.x = p.y = p.z = 0.f; // a return at the sensor: none
  scan.push_back(p);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(10.0, 0.0, 0.0);
  support.addScan(scan, T);
  EXPECT_EQ(support.cells(), 1u);
  EXPECT_TRUE(support.supports({11.2f, 0.2f, 0.2f}));
  EXPECT_TRUE(support.supports({11.7f, 0.6f, -0.3f})); // the next cell along each axis
  EXPECT_FALSE(support.supports({12.2f, 0.2f, 0.2f})); // two cells on
  EXPECT_FALSE(support.supports({10.f, 0.f, 0.f}));    // where the sensor was
}
