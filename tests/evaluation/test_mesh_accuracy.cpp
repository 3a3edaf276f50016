#include <msf/common/exceptions.h>
#include <msf/evaluation/mesh_accuracy.h>

#include "test_support.h"

#include <pcl/conversions.h>

#include <algorithm>
#include <array>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace {

/// A square [0, size]^2 in the plane z = height, split into n x n cells of two triangles.
pcl::PolygonMesh gridSquare(float size, int n, float height) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      cloud.push_back(pcl::PointXYZ(size * i / n, size * j / n, height));
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(cloud, mesh.cloud);
  using Index = decltype(pcl::Vertices::vertices)::value_type;
  auto id = [n](int i, int j) { return static_cast<Index>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      for (const auto& corners : {std::array<Index, 3>{id(i, j), id(i + 1, j), id(i + 1, j + 1)},
                                  std::array<Index, 3>{id(i, j), id(i + 1, j + 1), id(i, j + 1)}}) {
        pcl::Vertices triangle;
        triangle.vertices.resize(3);
        std::copy(corners.begin(), corners.end(), triangle.vertices.begin());
        mesh.polygons.push_back(triangle);
      }
    }
  return mesh;
}

TEST(SurfaceDistance, ExactPointToTriangleDistances) {
  const msf::SurfaceDistance surface(gridSquare(2.f, 1, 0.f), 0.5f);
  EXPECT_NEAR(surface.distance({0.5f, 0.7f, 0.3f}, 5.f), 0.3f, 1e-6);  // above the face
  EXPECT_NEAR(surface.distance({3.f, 1.f, 0.f}, 5.f), 1.f, 1e-6);      // beside an edge
  EXPECT_NEAR(surface.distance({3.f, 3.f, 1.f}, 5.f), std::sqrt(3.f), 1e-5); // off a corner
  EXPECT_EQ(surface.distance({10.f, 10.f, 10.f}, 0.5f), 0.5f);          // capped
}

TEST(MeshAccuracy, OffsetPlaneGivesItsOffsetAndPartialCompleteness) {
  const pcl::PolygonMesh truth = gridSquare(4.f, 8, 0.f);
  // The reconstruction covers half of the square, 2 cm above it.
  const pcl::PolygonMesh mesh = gridSquare(2.f, 10, 0.02f);
  std::vector<Eigen::Vector3f> seen;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i)
      seen.emplace_back(4.f * (i + 0.5f) / 40, 4.f * (j + 0.5f) / 40, 0.f);
  const msf::MeshAccuracy a = msf::evaluateMesh(mesh, truth, seen, 0.05, 1.0);
  EXPECT_EQ(a.vertices, 121u);
  EXPECT_NEAR(a.accuracy_mean_m, 0.02, 1e-6);
  EXPECT_NEAR(a.accuracy_median_m, 0.02, 1e-6);
  EXPECT_DOUBLE_EQ(a.precision, 1.0);
  EXPECT_EQ(a.truth_samples, 1600u);
  // Samples with x, y in [0, 2] (and within 5 cm beyond its border... none at 4/80 spacing
  // except those at 2.05 m, which are 5 cm away: not strictly within).
  EXPECT_NEAR(a.completeness, 0.25, 1e-9);
}

TEST(MeshAccuracy, CompletenessByTheNearestDistanceASurfaceWasSeenFrom) {
  // The same square; every sample seen from 25 m, and those with x, y < 2 also from 5 m (a
  // second frame's samples at the same places). The mesh covers x, y < 2: what was seen near
  // is complete, what was seen only from far is not.
  const pcl::PolygonMesh truth = gridSquare(4.f, 8, 0.f);
  const pcl::PolygonMesh mesh = gridSquare(2.f, 10, 0.02f);
  std::vector<Eigen::Vector3f> seen;
  std::vector<float> depth;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) {
      const Eigen::Vector3f p(4.f * (i + 0.5f) / 40, 4.f * (j + 0.5f) / 40, 0.f);
      seen.push_back(p);
      depth.push_back(25.f);
      if (p.x() < 2.f && p.y() < 2.f) {
        seen.push_back(p);
        depth.push_back(5.f);
      }
    }
  const std::vector<float> nearest = msf::nearestViewDistance(seen, depth, 0.1f);
  ASSERT_EQ(nearest.size(), seen.size());
  for (std::size_t i = 0; i < seen.size(); ++i)
    EXPECT_EQ(nearest[i], seen[i].x() < 2.f && seen[i].y() < 2.f ? 5.f : 25.f);
  const msf::MeshAccuracy a = msf::evaluateMesh(mesh, truth, seen, 0.05, 1.0, 200000, &nearest);
  ASSERT_EQ(a.by_view_distance.size(), 3u); // 0-10, 10-20, 20-30 m
  EXPECT_EQ(a.by_view_distance[0].samples, 800u);
  EXPECT_DOUBLE_EQ(a.by_view_distance[0].completeness, 1.0);
  EXPECT_EQ(a.by_view_distance[1].samples, 0u);
  EXPECT_EQ(a.by_view_distance[2].samples, 1200u);
  EXPECT_DOUBLE_EQ(a.by_view_distance[2].completeness, 0.0);
  EXPECT_DOUBLE_EQ(a.by_view_distance[2].upper_m, 30.0);
  // Sizes that differ are refused by name.
  depth.pop_back();
  EXPECT_EQ(msf::test::errorOf([&] { msf::nearestViewDistance(seen, depth, 0.1f); }),
            "nearest view distance: 1999 depths for 2000 points");
  EXPECT_THROW(msf::evaluateMesh(mesh, truth, seen, 0.05, 1.0, 200000, &depth), msf::InvalidInputError);
}

TEST(MeshAccuracy, EmptyMeshIsAnError) {
  EXPECT_THROW(msf::evaluateMesh(pcl::PolygonMesh(), gridSquare(1.f, 1, 0.f), {}, 0.1), msf::InvalidInputError);
  EXPECT_THROW(msf::SurfaceDistance(pcl::PolygonMesh()), msf::InvalidInputError);
}

} // namespace
