// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
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

/// Two strips over the square [0, 4]^2 as one mesh: x in [0, 2] on the plane z = 0, and x in
/// [2, 4] at z = 0.1; each n x 2n cells of two triangles.
pcl::PolygonMesh twoStrips(int n) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::PolygonMesh mesh;
  using Index = decltype(pcl::Vertices::vertices)::value_type;
  for (int strip = 0; strip < 2; ++strip) {
    const auto first = static_cast<Index>(cloud.size());
    for (int j = 0; j <= 2 * n; ++j)
      for (int i = 0; i <= n; ++i)
        cloud.push_back(pcl::PointXYZ(2.f * strip + 2.f * i / n, 4.f * j / (2 * n), 0.1f * strip));
    auto id = [&](int i, int j) { return static_cast<Index>(first + j * (n + 1) + i); };
    for (int j = 0; j < 2 * n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& corners : {std::array<Index, 3>{id(i, j), id(i + 1, j), id(i + 1, j + 1)},
                                    std::array<Index, 3>{id(i, j), id(i + 1, j + 1), id(i, j + 1)}}) {
          pcl::Vertices triangle;
          triangle.vertices.assign(corners.begin(), corners.end());
          mesh.polygons.push_back(triangle);
        }
  }
  pcl::toPCLPointCloud2(cloud, mesh.cloud);
  return mesh;
}

TEST(MeshAccuracy, TheWeightCurveKeepsTheSurestSurface) {
  // The strip on the truth weighs 500 (LiDAR-like), the one 10 cm off it 3 (far stereo): as
  // the bar passes 3 the mesh keeps the exact strip only, half as complete, with no error.
  const pcl::PolygonMesh truth = gridSquare(4.f, 8, 0.f), mesh = twoStrips(10);
  const std::size_t strip_vertices = 11 * 21;
  std::vector<float> weights(2 * strip_vertices, 500.f);
  std::fill(weights.begin() + static_cast<std::ptrdiff_t>(strip_vertices), weights.end(), 3.f);
  std::vector<Eigen::Vector3f> seen;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i)
      seen.emplace_back(4.f * (i + 0.5f) / 40, 4.f * (j + 0.5f) / 40, 0.f);
  const msf::MeshAccuracy a = msf::evaluateMesh(mesh, truth, seen, 0.12, 1.0, 200000, nullptr, &weights);
  ASSERT_FALSE(a.by_weight.empty());
  // The whole mesh: what evaluateMesh gives.
  const msf::WeightLevel whole = a.by_weight.atWeight(0.0);
  EXPECT_EQ(whole.vertices, 2 * strip_vertices);
  EXPECT_NEAR(whole.accuracy_mean_m, a.accuracy_mean_m, 1e-9);
  EXPECT_NEAR(whole.accuracy_mean_m, 0.05, 1e-6);
  EXPECT_DOUBLE_EQ(whole.completeness, a.completeness);
  EXPECT_DOUBLE_EQ(whole.completeness, 1.0);
  EXPECT_EQ(a.by_weight.atWeight(3.0).vertices, 2 * strip_vertices); // a bar keeps what weighs it
  // Above 3: the exact strip, and the samples within 12 cm of it (x < 2.12: 21 of 40 columns).
  for (const double bar : {3.5, 100.0, 500.0}) {
    const msf::WeightLevel sure = a.by_weight.atWeight(bar);
    EXPECT_EQ(sure.vertices, strip_vertices) << bar;
    EXPECT_NEAR(sure.accuracy_mean_m, 0.0, 1e-6) << bar;
    EXPECT_DOUBLE_EQ(sure.completeness, 21.0 / 40.0) << bar;
  }
  const msf::WeightLevel none = a.by_weight.atWeight(501.0);
  EXPECT_EQ(none.vertices, 0u);
  EXPECT_EQ(none.accuracy_mean_m, 0.0);
  EXPECT_EQ(none.completeness, 0.0);
  // The highest bar at a completeness: 500 up to 21 / 40, then 3, then the whole mesh.
  EXPECT_EQ(a.by_weight.atCompleteness(0.5).min_weight, 500.0);
  EXPECT_EQ(a.by_weight.atCompleteness(21.0 / 40.0).min_weight, 500.0);
  EXPECT_EQ(a.by_weight.atCompleteness(0.6).min_weight, 3.0);
  EXPECT_NEAR(a.by_weight.atCompleteness(0.6).accuracy_mean_m, 0.05, 1e-6);
  EXPECT_EQ(a.by_weight.atCompleteness(1.0).min_weight, 3.0);
  // A triangle goes with its lightest vertex; a vertex stays with its surest triangle.
  std::vector<float> one_light = std::vector<float>(2 * strip_vertices, 500.f);
  one_light[0] = 3.f; // the corner (0, 0): one triangle of the exact strip holds it
  const msf::MeshAccuracy b = msf::evaluateMesh(mesh, truth, seen, 0.12, 1.0, 200000, nullptr, &one_light);
  EXPECT_EQ(b.by_weight.atWeight(100.0).vertices, 2 * strip_vertices - 1);
  EXPECT_EQ(b.by_weight.atWeight(0.0).vertices, 2 * strip_vertices);

  // Weights that are not one per vertex are refused by name.
  weights.pop_back();
  EXPECT_EQ(msf::test::errorOf([&] { msf::evaluateMesh(mesh, truth, seen, 0.12, 1.0, 200000, nullptr, &weights); }),
            "mesh evaluation: 461 vertex weights for 462 vertices");
  const msf::SurfaceDistance surface(truth);
  EXPECT_EQ(msf::test::errorOf([&] { surface.highestWithin({1.f, 1.f, 0.f}, 0.1f, {1.f}, -1.f); }),
            "surface distance: 1 values for 128 triangles");
  EXPECT_THROW(msf::WeightCurve({1.f}, {1.f, 2.f}, {0.0}), msf::InvalidInputError);
}

/// Two meshes as one: b's vertices and triangles after a's.
pcl::PolygonMesh joined(const pcl::PolygonMesh& a, const pcl::PolygonMesh& b) {
  pcl::PointCloud<pcl::PointXYZ> ca, cb;
  pcl::fromPCLPointCloud2(a.cloud, ca);
  pcl::fromPCLPointCloud2(b.cloud, cb);
  pcl::PolygonMesh out;
  out.polygons = a.polygons;
  for (pcl::Vertices t : b.polygons) {
    for (auto& i : t.vertices)
      i += static_cast<std::uint32_t>(ca.size());
    out.polygons.push_back(t);
  }
  ca += cb;
  pcl::toPCLPointCloud2(ca, out.cloud);
  return out;
}

TEST(SurfaceDistance, NamesTheNearestTriangle) {
  const msf::SurfaceDistance surface(gridSquare(2.f, 1, 0.f), 0.5f); // triangles 0 (x > y) and 1 (x < y)
  std::uint32_t nearest = 7;
  EXPECT_NEAR(surface.distance({1.5f, 0.5f, 0.2f}, 5.f, &nearest), 0.2f, 1e-6);
  EXPECT_EQ(nearest, 0u);
  surface.distance({0.5f, 1.5f, -0.1f}, 5.f, &nearest);
  EXPECT_EQ(nearest, 1u);
  surface.distance({10.f, 10.f, 10.f}, 0.5f, &nearest);
  EXPECT_EQ(nearest, msf::SurfaceDistance::kNoTriangle);
}

TEST(MeshAccuracy, ByClassSplitsTheMeanIntoPartsThatAddUpToIt) {
  // The truth: a ground square (class 0) at z = 0 and a wall square (class 1) at z = 5.
  const pcl::PolygonMesh ground = gridSquare(4.f, 4, 0.f), wall = gridSquare(4.f, 4, 5.f);
  const pcl::PolygonMesh truth = joined(ground, wall);
  msf::SurfaceClasses classes;
  classes.names = {"ground", "wall"};
  classes.vertex_class.assign(25, 0);
  classes.vertex_class.resize(50, 1);
  // The mesh: the ground 3 cm above it (121 vertices) and a speck of 4 vertices 2.5 m from both.
  const pcl::PolygonMesh mesh = joined(gridSquare(4.f, 10, 0.03f), gridSquare(0.1f, 1, 2.5f));
  std::vector<Eigen::Vector3f> seen;
  for (int i = 0; i < 10; ++i) {
    seen.emplace_back(0.4f * i + 0.2f, 1.f, 0.f); // on the ground: covered
    seen.emplace_back(0.4f * i + 0.2f, 1.f, 5.f); // on the wall: not
  }
  const msf::MeshAccuracy a = msf::evaluateMesh(mesh, truth, seen, 0.1, 1.0, 200000, nullptr, nullptr, &classes);
  ASSERT_EQ(a.by_class.size(), 3u);
  const msf::ClassAccuracy &g = a.by_class[0], &w = a.by_class[1], &off = a.by_class[2];
  EXPECT_EQ(g.name, "ground");
  EXPECT_EQ(g.vertices, 121u);
  EXPECT_NEAR(g.accuracy_mean_m, 0.03, 1e-6);
  EXPECT_EQ(g.truth_samples, 10u);
  EXPECT_DOUBLE_EQ(g.completeness, 1.0);
  EXPECT_EQ(w.name, "wall");
  EXPECT_EQ(w.vertices, 0u);
  EXPECT_EQ(w.truth_samples, 10u);
  EXPECT_DOUBLE_EQ(w.completeness, 0.0);
  EXPECT_EQ(off.name, msf::ClassAccuracy::kOffSurface);
  EXPECT_EQ(off.vertices, 4u);
  EXPECT_DOUBLE_EQ(off.accuracy_mean_m, 1.0); // at the cap
  EXPECT_EQ(off.truth_samples, 0u);
  EXPECT_NEAR(g.contribution_m + w.contribution_m + off.contribution_m, a.accuracy_mean_m, 1e-9);
  EXPECT_NEAR(off.contribution_m, 4.0 / 125.0, 1e-9);
}

TEST(MeshAccuracy, ClassesThatDoNotFitTheTruthAreAnError) {
  const pcl::PolygonMesh truth = gridSquare(1.f, 1, 0.f); // 4 vertices
  msf::SurfaceClasses classes;
  classes.names = {"ground"};
  classes.vertex_class = {0, 0, 0};
  EXPECT_THROW(msf::evaluateMesh(truth, truth, {}, 0.1, 1.0, 200000, nullptr, nullptr, &classes),
               msf::InvalidInputError);
  classes.vertex_class = {0, 0, 0, 1}; // class 1 of 1 name
  EXPECT_THROW(msf::evaluateMesh(truth, truth, {}, 0.1, 1.0, 200000, nullptr, nullptr, &classes),
               msf::InvalidInputError);
}

TEST(MeshAccuracy, EmptyMeshIsAnError) {
  EXPECT_THROW(msf::evaluateMesh(pcl::PolygonMesh(), gridSquare(1.f, 1, 0.f), {}, 0.1), msf::InvalidInputError);
  EXPECT_THROW(msf::SurfaceDistance(pcl::PolygonMesh()), msf::InvalidInputError);
}

} // namespace
