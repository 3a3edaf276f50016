// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_components.h>

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace msf;

namespace {

/// A strip of `quads` unit squares along x at height z (2 triangles each, one piece), with
/// every vertex coloured `red`.
void addStrip(TriangleMesh& mesh, int quads, float z, std::uint8_t red) {
  const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
  for (int i = 0; i <= quads; ++i)
    for (int j = 0; j < 2; ++j) {
      mesh.vertices.emplace_back(static_cast<float>(i), static_cast<float>(j), z);
      mesh.colors.push_back({red, 0, 0});
    }
  for (int i = 0; i < quads; ++i) {
    const std::uint32_t a = first + 2 * i, b = a + 1, c = a + 2, d = a + 3;
    mesh.triangles.push_back({a, c, b});
    mesh.triangles.push_back({b, c, d});
  }
}

/// The z of each triangle's vertices, which must all be the same.
std::multiset<float> triangleHeights(const TriangleMesh& mesh) {
  std::multiset<float> z;
  for (const auto& t : mesh.triangles) {
    EXPECT_EQ(mesh.vertices[t[0]].z(), mesh.vertices[t[1]].z());
    EXPECT_EQ(mesh.vertices[t[0]].z(), mesh.vertices[t[2]].z());
    z.insert(mesh.vertices[t[0]].z());
  }
  return z;
}

} // namespace

TEST(MeshComponents, RemovesThePiecesBelowTheSizeAndKeepsTheOthersIntact) {
  TriangleMesh mesh;
  addStrip(mesh, 2, 5.f, 50);   // 4 triangles
  addStrip(mesh, 10, 0.f, 10);  // 20 triangles
  addStrip(mesh, 1, 7.f, 70);   // 2 triangles
  addStrip(mesh, 12, 3.f, 30);  // 24 triangles
  const ComponentFilterStats stats = removeSmallComponents(mesh, 20);
  EXPECT_EQ(stats.components, 4u);
  EXPECT_EQ(stats.components_removed, 2u);
  EXPECT_EQ(stats.triangles_removed, 6u);
  EXPECT_EQ(stats.vertices_removed, 6u + 4u);
  ASSERT_EQ(mesh.triangles.size(), 44u);
  ASSERT_EQ(mesh.vertices.size(), 22u + 26u);
  ASSERT_EQ(mesh.colors.size(), mesh.vertices.size());
  // The 20-triangle strip (exactly the size) stays, and the order of what is kept is kept.
  const std::multiset<float> z = triangleHeights(mesh);
  EXPECT_EQ(z.count(0.f), 20u);
  EXPECT_EQ(z.count(3.f), 24u);
  EXPECT_EQ(mesh.vertices.front().z(), 0.f);
  EXPECT_EQ(mesh.vertices.back().z(), 3.f);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    EXPECT_EQ(mesh.colors[v][0], mesh.vertices[v].z() == 0.f ? 10 : 30) << v;
}

TEST(MeshComponents, PiecesJoinThroughASharedVertexOnly) {
  // Two 4-triangle strips that share one corner vertex are one piece of 8 triangles.
  TriangleMesh mesh;
  addStrip(mesh, 2, 0.f, 1);
  addStrip(mesh, 2, 0.f, 2);
  const std::uint32_t shared = 0, other_first = 6;
  for (auto& t : mesh.triangles)
    for (auto& v : t)
      if (v == other_first + 5)
        v = shared;
  EXPECT_EQ(removeSmallComponents(mesh, 8).components_removed, 0u);
  EXPECT_EQ(mesh.triangles.size(), 8u);
  EXPECT_EQ(removeSmallComponents(mesh, 9).components_removed, 1u);
  EXPECT_TRUE(mesh.triangles.empty());
  EXPECT_TRUE(mesh.vertices.empty());
}

TEST(MeshComponents, EachVertexIsLabelledByItsPiecesSmallestVertex) {
  // Two strips of 3 and 4 vertex pairs, and a vertex no triangle uses.
  TriangleMesh mesh;
  addStrip(mesh, 2, 0.f, 1);
  addStrip(mesh, 3, 1.f, 2);
  mesh.vertices.emplace_back(9.f, 9.f, 9.f);
  const std::vector<std::uint32_t> label = componentLabels(mesh);
  ASSERT_EQ(label.size(), 15u);
  for (std::uint32_t v = 0; v < 6; ++v)
    EXPECT_EQ(label[v], 0u);
  for (std::uint32_t v = 6; v < 14; ++v)
    EXPECT_EQ(label[v], 6u);
  EXPECT_EQ(label[14], 14u);
  mesh.triangles.push_back({0, 1, 15});
  EXPECT_THROW(componentLabels(mesh), InvalidInputError);
}

TEST(MeshComponents, ZeroOrOneKeepsEverything) {
  TriangleMesh mesh;
  addStrip(mesh, 1, 0.f, 1);
  addStrip(mesh, 3, 1.f, 1);
  for (const std::size_t min : {0u, 1u, 2u}) {
    TriangleMesh copy = mesh;
    const ComponentFilterStats stats = removeSmallComponents(copy, min);
    EXPECT_EQ(stats.components, 2u);
    EXPECT_EQ(stats.components_removed, 0u);
    EXPECT_EQ(copy.triangles, mesh.triangles);
    EXPECT_EQ(copy.vertices.size(), mesh.vertices.size());
  }
  TriangleMesh empty;
  EXPECT_EQ(removeSmallComponents(empty, 20).components, 0u);
}

TEST(MeshComponents, RejectsAMeshThatIsNotConsistent) {
  TriangleMesh mesh;
  addStrip(mesh, 1, 0.f, 1);
  mesh.triangles[1][2] = 9;
  try {
    removeSmallComponents(mesh, 2);
    FAIL() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 1 names vertex 9 of 4"), std::string::npos) << e.what();
  }
  mesh.triangles[1][2] = 3;
  mesh.colors.pop_back();
  EXPECT_THROW(removeSmallComponents(mesh, 2), InvalidInputError);
}

TEST(MeshComponents, MarchingCubesRemovesSpecksAndReportsThem) {
  // A plane sdf = 0.25 - z over 2 x 2 blocks and, far from it, one block with a single
  // voxel of negative sdf: a speck of 8 triangles (an octahedron around the voxel).
  TsdfVolume volume(0.1, 0.5);
  const auto fill = [&](const GridIndex& index, auto sdf) {
    TsdfBlock& block = volume.allocateBlock(index);
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          TsdfVoxel& v = block.at(x, y, z);
          v.sdf = sdf(x, y, z);
          v.weight = 100.f; // an inverse variance (m^-2) above the default min_weight
        }
    block.stamp = volume.beginGeneration();
    block.updateSigns();
  };
  for (int bx = -1; bx <= 0; ++bx)
    for (int by = -1; by <= 0; ++by)
      fill(GridIndex(bx, by, 0), [](int, int, int z) { return 0.25f - 0.1f * static_cast<float>(z); });
  fill(GridIndex(5, 5, 5), [](int x, int y, int z) { return x == 4 && y == 4 && z == 4 ? -0.05f : 0.05f; });

  MarchingCubes::Config config;
  config.min_component_triangles = 0;
  TriangleMesh all;
  MarchingCubes(config).extract(volume, all);
  EXPECT_EQ(all.triangles.size(), 450u + 8u);

  config.min_component_triangles = 20;
  MarchingCubes mesher(config);
  TriangleMesh clean;
  mesher.extract(volume, clean);
  EXPECT_EQ(clean.triangles.size(), 450u);
  EXPECT_EQ(clean.vertices.size(), 256u);
  EXPECT_EQ(mesher.lastStats().components_removed, 1u);
  EXPECT_EQ(mesher.lastStats().triangles_removed, 8u);
  for (const auto& p : clean.vertices)
    EXPECT_NEAR(p.z(), 0.25f, 1e-6);
  ASSERT_EQ(clean.weights.size(), clean.vertices.size());
  for (const float w : clean.weights)
    EXPECT_EQ(w, 100.f); // the lesser weight of the crossing's two voxels

  // Known precisely (a pole the LiDAR saw, 1000 m^-2: sigma 3 cm), the same speck is kept by the
  // default component_keep_weight (300); with 0, no piece is kept for its weight.
  ASSERT_EQ(config.component_keep_weight, 300.f);
  TsdfBlock& speck = *volume.findBlock(GridIndex(5, 5, 5));
  for (int z = 3; z <= 5; ++z)
    for (int y = 3; y <= 5; ++y)
      for (int x = 3; x <= 5; ++x)
        speck.at(x, y, z).weight = 1000.f;
  speck.stamp = volume.beginGeneration();
  TriangleMesh precise;
  mesher.extract(volume, precise);
  EXPECT_EQ(precise.triangles.size(), 450u + 8u);
  EXPECT_EQ(mesher.lastStats().components_removed, 0u);
  config.component_keep_weight = 0.f;
  MarchingCubes(config).extract(volume, precise);
  EXPECT_EQ(precise.triangles.size(), 450u);
}

TEST(MeshComponents, ConfigRejectsANegativeSize) {
  MarchingCubes::Config config;
  EXPECT_EQ(config.min_component_triangles, 2000); // with component_keep_weight: floating pieces, not what the LiDAR saw
  for (const float bad : {-1.f, NAN, INFINITY}) {
    MarchingCubes::Config c;
    c.component_keep_weight = bad;
    try {
      c.validate();
      ADD_FAILURE() << "accepted component_keep_weight " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("marching_cubes.component_keep_weight must be >= 0"), std::string::npos)
          << e.what();
    }
  }
  config.min_component_triangles = -1;
  try {
    MarchingCubes mesher(config);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("marching_cubes.min_component_triangles must be >= 0, not -1"),
              std::string::npos)
        << e.what();
  }
}
