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

TEST(MeshComponents, AClosedBubbleWithinTheExtentGoesWhateverItsWeightAndAnOpenFragmentStays) {
  // Heavy (the LiDAR's weight) and small: a tetrahedron of 5 cm, closed; a 5 cm square of two
  // triangles, open; a 1 m strip of 2 triangles, open, too long for the extent.
  TriangleMesh mesh;
  const auto add = [&mesh](std::initializer_list<Eigen::Vector3f> points) {
    for (const Eigen::Vector3f& p : points) {
      mesh.vertices.push_back(p);
      mesh.colors.push_back({1, 2, 3});
      mesh.weights.push_back(1000.f);
    }
  };
  add({{0, 0, 0}, {0.05f, 0, 0}, {0, 0.05f, 0}, {0, 0, 0.05f}});
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  add({{5, 0, 0}, {5.05f, 0, 0}, {5, 0.05f, 0}, {5.05f, 0.05f, 0}});
  mesh.triangles.push_back({4, 5, 6});
  mesh.triangles.push_back({5, 7, 6});
  add({{9, 0, 0}, {10, 0, 0}, {9, 0.05f, 0}});
  mesh.triangles.push_back({8, 9, 10});

  TriangleMesh kept = mesh;
  EXPECT_EQ(removeSmallComponents(kept, 2000, 300.f).components_removed, 0u); // the weight keeps all
  const ComponentFilterStats stats = removeSmallComponents(mesh, 2000, 300.f, 0.3f);
  EXPECT_EQ(stats.components, 3u);
  EXPECT_EQ(stats.components_removed, 1u);
  EXPECT_EQ(stats.triangles_removed, 4u);
  ASSERT_EQ(mesh.triangles.size(), 3u);
  ASSERT_EQ(mesh.vertices.size(), 7u);
  EXPECT_EQ(mesh.vertices.front().x(), 5.f); // the tetrahedron went, the square and the strip stay
  EXPECT_EQ(mesh.weights.size(), 7u);
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

  // Known precisely (1000 m^-2: sigma 3 cm), the speck is still one voxel of flipped sign, within
  // the default min_component_extent_voxels (3): removed whatever its weight; kept for its weight
  // (the default component_keep_weight, 300) with the extent rule off.
  ASSERT_EQ(config.component_keep_weight, 300.f);
  ASSERT_EQ(config.min_component_extent_voxels, 3.f);
  TsdfBlock& speck = *volume.findBlock(GridIndex(5, 5, 5));
  const auto setPrecise = [&](int x0, int x1, int y0, int y1, int z0, int z1) {
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          speck.at(x, y, z).weight = 1000.f;
    speck.stamp = volume.beginGeneration();
  };
  setPrecise(3, 5, 3, 5, 3, 5);
  TriangleMesh precise;
  mesher.extract(volume, precise);
  EXPECT_EQ(precise.triangles.size(), 450u);
  EXPECT_EQ(mesher.lastStats().components_removed, 1u);
  MarchingCubes::Config extent_off = config;
  extent_off.min_component_extent_voxels = 0.f;
  MarchingCubes(extent_off).extract(volume, precise);
  EXPECT_EQ(precise.triangles.size(), 450u + 8u);
  config.component_keep_weight = 0.f;
  config.min_component_extent_voxels = 0.f;
  MarchingCubes(config).extract(volume, precise);
  EXPECT_EQ(precise.triangles.size(), 450u);

  // A pole the LiDAR saw: the voxel column x = y = 4, z = 1..6, 0.5 m tall, a small piece that
  // its weight keeps at the default extent rule.
  for (int z = 1; z <= 6; ++z)
    speck.at(4, 4, z).sdf = -0.05f;
  setPrecise(3, 5, 3, 5, 0, 7);
  speck.updateSigns();
  MarchingCubes::Config defaults;
  defaults.min_component_triangles = 20;
  MarchingCubes pole_mesher(defaults);
  pole_mesher.extract(volume, precise);
  EXPECT_EQ(pole_mesher.lastStats().components_removed, 0u);
  EXPECT_GT(precise.triangles.size(), 450u + 20u);
  EXPECT_LT(precise.triangles.size(), 450u + 2000u);
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
