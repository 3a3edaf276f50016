// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>

using namespace msf;

namespace {

void integrateSphere(TsdfVolume& volume, int first, int count, MarchingCubes* mesher = nullptr,
                     TriangleMesh* mesh = nullptr) {
  const AnalyticScene scene = test::makeScene(test::SceneKind::Sphere);
  TsdfIntegrator integrator(volume);
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 40, 8);
  for (int i = first; i < first + count; ++i) {
    DepthFrame frame = test::renderFrame(scene, test::smallCamera(), poses[i]);
    frame.color = cv::Mat(frame.depth.size(), CV_8UC3, cv::Scalar(30 * i, 20, 255 - 30 * i));
    integrator.integrate(frame, poses[i]);
    if (mesher)
      mesher->extract(volume, *mesh);
  }
}

} // namespace

/// sdf = 0.25 - z on a 0.1 m grid over 2 x 2 blocks, the first at `corner`.
TsdfVolume planeOnTheGrid(const GridIndex& corner = GridIndex(-1, -1, 0)) {
  TsdfVolume volume(0.1, 0.5);
  for (int bx = 0; bx <= 1; ++bx)
    for (int by = 0; by <= 1; ++by) {
      TsdfBlock& block = volume.allocateBlock(corner + GridIndex(bx, by, 0));
      for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) {
            TsdfVoxel& v = block.at(x, y, z);
            v.sdf = 0.25f - 0.1f * static_cast<float>(z);
            v.weight = 100.f; // an inverse variance (m^-2) above the default min_weight
          }
      block.stamp = volume.beginGeneration();
      block.updateSigns();
    }
  return volume;
}

TriangleMesh wholeMeshOf(const TsdfVolume& volume) {
  TriangleMesh mesh;
  MarchingCubes::Config whole; // the plane is a small piece no precise vertex holds: not filtered here
  whole.min_component_triangles = 0;
  MarchingCubes(whole).extract(volume, mesh);
  return mesh;
}

TEST(MarchingCubes, PlaneOnTheGridGivesExactVertices) {
  // sdf = 0.25 - z on a 0.1 m grid: vertices at z = 0.25 exactly, triangles facing -z
  // (towards positive sdf, the side the camera would see).
  const TriangleMesh mesh = wholeMeshOf(planeOnTheGrid());
  // 16 x 16 voxel columns -> 15 x 15 cubes -> 225 squares -> 450 triangles, 256 vertices.
  EXPECT_EQ(mesh.triangles.size(), 450u);
  EXPECT_EQ(mesh.vertices.size(), 256u);
  for (const auto& p : mesh.vertices)
    EXPECT_NEAR(p.z(), 0.25f, 1e-6);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    EXPECT_LT(n.z(), 0.f);
  }
}

TEST(MarchingCubes, APlaneFarFromTheOriginIsWeldedAsNearIt) {
  // The same plane 64 km from the origin along -y and 60 km along +x (within the volume's reach):
  // its vertices are welded as at the origin, none merged with another.
  for (const GridIndex& corner : {GridIndex(0, -80000, 0), GridIndex(75000, 0, 0), GridIndex(-80000, 80000, 3)}) {
    const TriangleMesh mesh = wholeMeshOf(planeOnTheGrid(corner));
    EXPECT_EQ(mesh.triangles.size(), 450u) << corner.transpose();
    EXPECT_EQ(mesh.vertices.size(), 256u) << corner.transpose();
  }
}

TEST(MarchingCubes, MeshIsWeldedOrientedAndManifold) {
  TsdfVolume volume(0.04, 0.12);
  integrateSphere(volume, 0, 8);
  TriangleMesh mesh;
  MarchingCubes mesher;
  mesher.extract(volume, mesh);
  ASSERT_GT(mesh.triangles.size(), 5000u);
  // No two vertices at the same position, every vertex used, no degenerate triangle.
  std::set<std::array<float, 3>> positions;
  for (const auto& p : mesh.vertices)
    positions.insert({p.x(), p.y(), p.z()});
  EXPECT_EQ(positions.size(), mesh.vertices.size());
  std::vector<int> used(mesh.vertices.size(), 0);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : mesh.triangles) {
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    for (int k = 0; k < 3; ++k) {
      used[t[k]] = 1;
      const auto a = t[k], b = t[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);
  std::size_t interior = 0;
  for (const auto& [edge, count] : edges) {
    EXPECT_LE(count, 2);
    interior += count == 2;
  }
  EXPECT_GT(interior, edges.size() * 9 / 10); // welded: most edges are shared by two triangles
  // Outward normals on the sphere.
  std::size_t outward = 0, on_sphere = 0;
  const Eigen::Vector3f centre(0, 0, 2.5f);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f c = (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.f;
    if (std::abs((c - centre).norm() - 0.5f) > 0.02f)
      continue;
    ++on_sphere;
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    outward += n.dot(c - centre) > 0.f;
  }
  ASSERT_GT(on_sphere, 500u);
  EXPECT_EQ(outward, on_sphere);
}

TEST(MarchingCubes, IncrementalMeshingEqualsFullMeshing) {
  TsdfVolume volume(0.04, 0.12);
  MarchingCubes incremental;
  TriangleMesh mesh;
  integrateSphere(volume, 0, 6, &incremental, &mesh);
  const std::size_t blocks_last_call = incremental.lastStats().blocks_meshed;
  EXPECT_GT(incremental.lastStats().blocks_cached, 0u);
  EXPECT_LT(blocks_last_call, volume.numBlocks());

  TriangleMesh full;
  MarchingCubes().extract(volume, full);
  ASSERT_GT(full.triangles.size(), 1000u);
  EXPECT_EQ(mesh.vertices, full.vertices);
  EXPECT_EQ(mesh.colors, full.colors);
  EXPECT_EQ(mesh.triangles, full.triangles);

  // Nothing changed: nothing is meshed again, and the mesh is the same.
  TriangleMesh again;
  incremental.extract(volume, again);
  EXPECT_EQ(incremental.lastStats().blocks_meshed, 0u);
  EXPECT_EQ(again.triangles, full.triangles);

  // Another volume through the same object: it starts over.
  TsdfVolume other(0.04, 0.12);
  integrateSphere(other, 2, 2);
  TriangleMesh other_incremental, other_full;
  incremental.extract(other, other_incremental);
  MarchingCubes().extract(other, other_full);
  EXPECT_EQ(other_incremental.triangles, other_full.triangles);
  EXPECT_EQ(other_incremental.vertices, other_full.vertices);
}

TEST(MarchingCubes, MinimumWeightDropsWeakVoxels) {
  TsdfVolume volume(0.04, 0.12);
  integrateSphere(volume, 0, 3);
  // Each frame of exact depth adds 1 / depth_sigma_m^2 to a voxel near the surface.
  const float frame_weight = static_cast<float>(1.0 / std::pow(TsdfIntegrator::Config().depth_sigma_m, 2));
  TriangleMesh all, strong, none;
  MarchingCubes().extract(volume, all);
  MarchingCubes::Config c;
  c.min_weight = 2.5f * frame_weight; // only voxels seen by all 3 frames
  MarchingCubes(c).extract(volume, strong);
  c.min_weight = 3.f * frame_weight;
  MarchingCubes(c).extract(volume, none);
  EXPECT_GT(all.triangles.size(), strong.triangles.size());
  EXPECT_GT(strong.triangles.size(), 100u);
  EXPECT_TRUE(none.triangles.empty());
  MarchingCubes::Config bad;
  bad.min_weight = -1.f;
  EXPECT_THROW(MarchingCubes{bad}, ConfigError);
}

namespace {

/// The plane sdf = 0.25 - z over one block (0.1 m voxels, weight 100), with `unseen` voxels
/// (x, y, z) at weight 0, as a frame's band leaves them behind a grazing surface.
TsdfVolume planeWithUnseenVoxels(const std::vector<std::array<int, 3>>& unseen) {
  TsdfVolume volume(0.1, 0.5);
  TsdfBlock& block = volume.allocateBlock(GridIndex(0, 0, 0));
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        TsdfVoxel& v = block.at(x, y, z);
        v.sdf = 0.25f - 0.1f * static_cast<float>(z);
        v.weight = 100.f;
      }
  for (const auto& u : unseen) {
    TsdfVoxel& v = block.at(u[0], u[1], u[2]);
    v.sdf = 0.f;
    v.weight = 0.f;
  }
  block.stamp = volume.beginGeneration();
  block.updateSigns();
  return volume;
}

TriangleMesh meshOf(const TsdfVolume& volume, int max_unseen_corners) {
  MarchingCubes::Config c;
  c.min_component_triangles = 0;
  c.smoothing_lambda = 0.f;
  c.max_unseen_corners = max_unseen_corners;
  TriangleMesh mesh;
  MarchingCubes(c).extract(volume, mesh);
  return mesh;
}

} // namespace

TEST(MarchingCubes, ACornerNoFrameReachedBehindTheSurfaceLeavesNoHole) {
  // 8 x 8 voxel columns -> 7 x 7 cubes -> 98 triangles at z = 0.25 (between voxel layers 2 and 3).
  EXPECT_EQ(meshOf(planeWithUnseenVoxels({}), 1).triangles.size(), 98u);
  // Voxel (3, 3, 3), just behind the plane, unseen: the 4 cubes around it lose it as a corner.
  const TsdfVolume one = planeWithUnseenVoxels({{3, 3, 3}});
  EXPECT_EQ(meshOf(one, 0).triangles.size(), 98u - 8u); // a hole of 4 cubes
  const TriangleMesh filled = meshOf(one, 1);
  ASSERT_EQ(filled.triangles.size(), 98u);
  // The unseen corner is taken a voxel behind the surface: the edges to it from the seen voxel
  // above (sdf 0.05) are crossed at 0.05 / (0.05 + 0.1) of the edge, z = 0.2 + 0.033; the others exact.
  ASSERT_EQ(filled.weights.size(), filled.vertices.size());
  std::size_t guessed = 0;
  for (std::size_t k = 0; k < filled.vertices.size(); ++k) {
    const float z = filled.vertices[k].z();
    if (filled.weights[k] > 0.f) {
      EXPECT_NEAR(z, 0.25f, 1e-5f);
    } else { // next to the unseen voxel: no evidence of its own
      ++guessed;
      EXPECT_NEAR(z, 0.2f + 0.1f / 3.f, 1e-5f);
      EXPECT_NEAR(filled.vertices[k].x(), 0.3f, 1e-5f);
      EXPECT_NEAR(filled.vertices[k].y(), 0.3f, 1e-5f);
    }
  }
  EXPECT_EQ(guessed, 1u);
  // Two unseen corners in one cube: filled only with max_unseen_corners 2.
  const TsdfVolume two = planeWithUnseenVoxels({{3, 3, 3}, {4, 3, 3}});
  EXPECT_LT(meshOf(two, 1).triangles.size(), 98u);
  EXPECT_EQ(meshOf(two, 2).triangles.size(), 98u);
  // A cube whose seen corners are all on one side (here all free space) is not a surface.
  const TsdfVolume free_corner = planeWithUnseenVoxels({{3, 3, 0}});
  EXPECT_EQ(meshOf(free_corner, 4).triangles, meshOf(planeWithUnseenVoxels({}), 4).triangles);
  MarchingCubes::Config bad;
  bad.max_unseen_corners = 5;
  EXPECT_NE(test::errorOf([&] { MarchingCubes{bad}; }).find("marching_cubes.max_unseen_corners must be in 0..4"),
            std::string::npos);
}

TEST(MarchingCubes, AMeshDoesNotDependOnWhichUnobservedBlocksWereAllocated) {
  // The plane sdf = 0.75 - z (between voxel layers 7 and 8, 0.1 m voxels) over the 2 x 2 x 2
  // blocks at the origin but block (1, 1, 1): cube (7, 7, 7) has one corner there, which no
  // frame reached. A run may have allocated that block and left it unobserved; a saved volume
  // omits it: the mesh is the same.
  const auto planeAcrossBlocks = [] {
    TsdfVolume volume(0.1, 0.5);
    for (int b = 0; b < 7; ++b) {
      TsdfBlock& block = volume.allocateBlock(GridIndex(b & 1, (b >> 1) & 1, (b >> 2) & 1));
      for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) {
            TsdfVoxel& v = block.at(x, y, z);
            v.sdf = 0.75f - 0.1f * static_cast<float>(block.origin().z() + z);
            v.weight = 100.f;
          }
      block.stamp = volume.beginGeneration();
      block.updateSigns();
    }
    return volume;
  };
  const TsdfVolume omitted = planeAcrossBlocks();
  TsdfVolume allocated = planeAcrossBlocks();
  allocated.allocateBlock(GridIndex(1, 1, 1));
  for (const int max_unseen : {0, 1}) {
    const TriangleMesh a = meshOf(omitted, max_unseen), b = meshOf(allocated, max_unseen);
    EXPECT_EQ(a.vertices, b.vertices) << max_unseen;
    EXPECT_EQ(a.triangles, b.triangles) << max_unseen;
  }
  // The corner counts as unseen: the cube is filled when one unseen corner is allowed.
  EXPECT_EQ(meshOf(omitted, 1).triangles.size(), meshOf(omitted, 0).triangles.size() + 2);
}

TEST(MarchingCubes, SmoothingMovesWhatIsUncertainAndKeepsWhatIsKnown) {
  // The sphere with 30 mm of depth noise, once said to be known to 1 cm (weight 1e4 a frame,
  // LiDAR-like) and once to 0.5 m (4 a frame, far-stereo-like): eq. 7 at meshing with each
  // voxel's data term weighed by its weight smooths the second and leaves the first.
  const AnalyticScene scene = test::makeScene(test::SceneKind::Sphere);
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, 5);
  auto volumeSaying = [&](double sigma_m) {
    TsdfVolume volume(0.04, 0.12);
    TsdfIntegrator::Config config;
    config.weighting = TsdfIntegrator::Weighting::Constant;
    config.depth_sigma_m = sigma_m;
    config.truncation_sigmas = 0.0; // the same band for both
    TsdfIntegrator integrator(volume, config);
    for (int i = 0; i < 5; ++i)
      integrator.integrate(test::renderFrame(scene, test::smallCamera(), poses[i], 0.03, 7 + i), poses[i]);
    return volume;
  };
  auto error = [&](const TsdfVolume& volume, float lambda) {
    MarchingCubes::Config c;
    c.min_weight = 0.f;
    c.smoothing_lambda = lambda;
    TriangleMesh mesh;
    MarchingCubes(c).extract(volume, mesh);
    EXPECT_GT(mesh.triangles.size(), 1000u);
    return test::meanVertexError(scene, mesh);
  };
  const TsdfVolume known = volumeSaying(0.01), unsure = volumeSaying(0.5);
  const double known_plain = error(known, 0.f), known_smoothed = error(known, 10.f);
  const double unsure_plain = error(unsure, 0.f), unsure_smoothed = error(unsure, 10.f);
  std::printf("  known to 1 cm: %.2f -> %.2f mm; to 0.5 m: %.2f -> %.2f mm\n", known_plain * 1e3,
              known_smoothed * 1e3, unsure_plain * 1e3, unsure_smoothed * 1e3);
  EXPECT_NEAR(known_smoothed, known_plain, 0.03 * known_plain);
  EXPECT_LT(unsure_smoothed, 0.8 * unsure_plain);

  // The volume is read, not changed: meshing again gives the same mesh.
  std::vector<float> before;
  for (const TsdfBlock* b : unsure.blocks())
    for (const TsdfVoxel& v : b->voxels)
      before.push_back(v.sdf);
  TriangleMesh first, second;
  MarchingCubes().extract(unsure, first);
  MarchingCubes().extract(unsure, second);
  std::vector<float> after;
  for (const TsdfBlock* b : unsure.blocks())
    for (const TsdfVoxel& v : b->voxels)
      after.push_back(v.sdf);
  EXPECT_EQ(before, after);
  EXPECT_EQ(first.vertices, second.vertices);

  for (const float bad : {-1.f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    MarchingCubes::Config c;
    c.smoothing_lambda = bad;
    try {
      MarchingCubes{c};
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("marching_cubes.smoothing_lambda"), std::string::npos) << e.what();
    }
  }
}

TEST(TriangleMesh, AMeshWithoutColoursIsSavedWithoutThemAndColoursNotOneAVertexAreRefused) {
  TriangleMesh triangle;
  triangle.vertices = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
  triangle.triangles = {{0, 1, 2}};
  pcl::PolygonMesh mesh;
  triangle.toPolygonMesh(mesh);
  ASSERT_EQ(mesh.cloud.fields.size(), 3u);
  EXPECT_EQ(mesh.cloud.point_step, 12u);
  test::TempDir dir;
  for (const char* name : {"grey.ply", "grey.obj", "grey.vtk"}) {
    saveMesh(dir.file(name), mesh);
    pcl::PolygonMesh back;
    loadMesh(dir.file(name), back);
    EXPECT_EQ(back.cloud.width * back.cloud.height, 3u) << name;
    EXPECT_EQ(back.polygons.size(), 1u) << name;
  }
  triangle.colors = {{255, 0, 0}};
  EXPECT_THROW(triangle.toPolygonMesh(mesh), InvalidInputError);
  EXPECT_EQ(test::errorOf([&] { triangle.toPolygonMesh(mesh); }),
            "a mesh of 3 vertices has 1 colours: one a vertex, or none");
}

TEST(MarchingCubes, PolygonMeshSavesAsPlyObjAndVtk) {
  TsdfVolume volume(0.04, 0.12);
  integrateSphere(volume, 0, 2);
  MarchingCubes mesher;
  pcl::PolygonMesh mesh;
  mesher.extract(volume, mesh);
  TriangleMesh triangles;
  mesher.extract(volume, triangles);
  ASSERT_EQ(mesh.polygons.size(), triangles.triangles.size());
  ASSERT_EQ(mesh.cloud.width, triangles.vertices.size());
  test::TempDir dir;
  for (const char* name : {"mesh.ply", "mesh.obj", "mesh.vtk"}) {
    saveMesh(dir.file(name), mesh);
    pcl::PolygonMesh back;
    loadMesh(dir.file(name), back);
    EXPECT_EQ(back.polygons.size(), mesh.polygons.size()) << name;
    EXPECT_EQ(back.cloud.width * back.cloud.height, mesh.cloud.width) << name;
  }
}
