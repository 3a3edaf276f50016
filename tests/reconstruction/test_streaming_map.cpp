// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_store.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

using namespace msf;

namespace {

constexpr double kVoxel = 0.2, kTruncation = 0.5, kMaxDepth = 8.0;
constexpr double kTile = 2 * TsdfBlock::kSide * kVoxel; // tile_blocks 2

/// The integrator of the drives. A least plane scale of 0.25 and constant weights (sigma 5 cm)
/// bound the band behind a surface to 0.8 m, so that the reach (13.6 m with the camera of 40 px
/// focal length) leaves a 60 m corridor room to stream.
TsdfIntegrator::Config integratorConfig() {
  TsdfIntegrator::Config config;
  config.max_depth_m = kMaxDepth;
  config.plane.min_scale = 0.25f;
  config.weighting = TsdfIntegrator::Weighting::Constant; // the frames have no weights: the same
  return config;
}

/// Poses along the corridor at `step` metres: forward from z = 0 to `length`, then (when
/// `back_to` >= 0) turned around and driven back to z = back_to.
std::vector<Eigen::Isometry3d> drive(double length, double step, double back_to = -1.0) {
  std::vector<Eigen::Isometry3d> poses;
  for (double z = 0; z <= length; z += step)
    poses.push_back(test::lookAt(Eigen::Vector3d(0.3 * std::sin(z), 0.0, z), Eigen::Vector3d(0, 0.3, z + 10)));
  if (back_to >= 0)
    for (double z = length; z >= back_to; z -= step)
      poses.push_back(test::lookAt(Eigen::Vector3d(-0.3, 0.0, z), Eigen::Vector3d(0, 0.3, z - 10)));
  return poses;
}

struct DriveResult {
  TriangleMesh mesh;
  std::size_t peak_blocks = 0;
  std::vector<std::size_t> blocks; ///< after each frame
  StreamingMap::Stats stats;
};

/// The corridor and the camera that drives it.
struct Corridor {
  double wall = 4.0;   ///< the walls' distance from the axis
  double focal = 40.0; ///< of the 64x48 camera
  double reach = 0.0;  ///< > 0: what the streaming map is told instead of the integrator's reach
  PinholeCamera camera() const { return test::centredCamera(64, 48, focal); }
};

/// The least radius of a streamed map of the drive, as the pipeline checks it: the
/// integrator's reach and a tile.
double minimumRadius(const Corridor& setup = Corridor()) {
  TsdfVolume volume(kVoxel, kTruncation);
  return TsdfIntegrator(volume, integratorConfig()).reach(setup.camera()) + kTile;
}

/// Integrates the drive; with `directory`, streamed with radius `radius` and the mesh read
/// back from the union the map writes (as written: welded by the map), else meshed in memory.
DriveResult integrateDrive(const std::vector<Eigen::Isometry3d>& poses, double length, const std::string& directory = "",
                   double radius = 0.0, const Corridor& setup = Corridor()) {
  const AnalyticScene scene = test::corridor(length + 10, setup.wall);
  TsdfVolume volume(kVoxel, kTruncation);
  TsdfIntegrator integrator(volume, integratorConfig());
  MarchingCubes::Config mesher;
  mesher.min_weight = 0.f;
  mesher.min_component_triangles = 0; // a streamed map keeps its small pieces: compared alike
  std::unique_ptr<StreamingMap> map;
  if (!directory.empty()) {
    StreamingMap::Config streaming;
    streaming.active_radius_m = radius;
    streaming.tile_blocks = 2;
    const double reach = setup.reach > 0.0 ? setup.reach : integrator.reach(setup.camera());
    map = std::make_unique<StreamingMap>(volume, streaming, mesher, reach, directory);
  }
  DriveResult run;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    DepthFrame frame = test::renderFrame(scene, setup.camera(), poses[i]);
    frame.depth.setTo(0.f, frame.depth > kMaxDepth - 0.5); // the far end of the corridor is not a surface
    frame.color = cv::Mat(frame.depth.size(), CV_8UC3, cv::Scalar(static_cast<double>(i % 200), 90, 200));
    if (map)
      map->beforeIntegration(poses[i].translation());
    integrator.integrate(frame, poses[i]);
    if (map)
      map->afterIntegration(poses[i].translation());
    run.blocks.push_back(volume.numBlocks());
    run.peak_blocks = std::max(run.peak_blocks, volume.numBlocks());
  }
  if (map) {
    const std::string path = directory + "/mesh.ply";
    EXPECT_GT(map->finish(path), 0u);
    EXPECT_EQ(volume.numBlocks(), 0u);
    StreamingMap::readMesh(path, run.mesh);
    run.stats = map->stats();
  } else {
    MarchingCubes(mesher).extract(volume, run.mesh);
  }
  return run;
}

using Point = std::array<float, 3>;
using Triangle = std::array<Point, 3>;

Point pointOf(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

/// Triangles by their vertices' positions, each rotated to start at its least vertex (the
/// orientation kept), sorted: equal for the same triangles in any order and welding.
std::vector<Triangle> triangleSet(const TriangleMesh& mesh) {
  std::vector<Triangle> out;
  for (const auto& t : mesh.triangles) {
    Triangle tri = {pointOf(mesh.vertices[t[0]]), pointOf(mesh.vertices[t[1]]), pointOf(mesh.vertices[t[2]])};
    const int first = static_cast<int>(std::min_element(tri.begin(), tri.end()) - tri.begin());
    std::rotate(tri.begin(), tri.begin() + first, tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Edges used by one triangle only, by their end positions.
std::set<std::pair<Point, Point>> boundaryEdges(const TriangleMesh& mesh) {
  std::map<std::pair<Point, Point>, int> uses;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      Point a = pointOf(mesh.vertices[t[k]]), b = pointOf(mesh.vertices[t[(k + 1) % 3]]);
      if (b < a)
        std::swap(a, b);
      ++uses[{a, b}];
    }
  std::set<std::pair<Point, Point>> out;
  for (const auto& [edge, n] : uses)
    if (n == 1)
      out.insert(edge);
  return out;
}

/// Edges used by one triangle only, by their vertex indices: on a mesh whose tiles are not
/// welded, every edge along a tile border is one of them (once per side).
std::size_t openEdgesByIndex(const TriangleMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  return static_cast<std::size_t>(std::count_if(uses.begin(), uses.end(), [](const auto& e) { return e.second == 1; }));
}

/// A union of tiles as one surface: as many vertices as the in-memory mesh, no two at the same
/// position, and the same open edges (by index), so no seam along a tile border.
void expectWelded(const TriangleMesh& union_mesh, const TriangleMesh& memory) {
  EXPECT_EQ(union_mesh.vertices.size(), memory.vertices.size());
  TriangleMesh welded = union_mesh;
  StreamingMap::weldByPosition(welded);
  EXPECT_EQ(welded.vertices.size(), union_mesh.vertices.size()) << "vertices at the same position";
  EXPECT_EQ(openEdgesByIndex(union_mesh), openEdgesByIndex(memory));
  EXPECT_TRUE(boundaryEdges(union_mesh) == boundaryEdges(memory));
}

} // namespace

TEST(TsdfVolumeRemove, RemovedBlocksAreGoneAndTheOthersKeepTheirVoxels) {
  TsdfVolume volume(0.1, 0.3);
  for (int i = 0; i < 1000; ++i) {
    TsdfBlock& block = volume.allocateBlock(GridIndex(i, -i, i % 7));
    block.voxels[i % TsdfBlock::kVoxels].weight = static_cast<float>(i + 1);
  }
  const std::size_t before = volume.memoryBytes();
  std::vector<GridIndex> gone;
  for (int i = 0; i < 1000; i += 3)
    gone.push_back(GridIndex(i, -i, i % 7));
  gone.push_back(GridIndex(5000, 0, 0)); // absent: ignored
  volume.removeBlocks(gone);
  EXPECT_EQ(volume.numBlocks(), 666u);
  EXPECT_LT(volume.memoryBytes(), before);
  for (int i = 0; i < 1000; ++i) {
    const TsdfBlock* block = volume.findBlock(GridIndex(i, -i, i % 7));
    if (i % 3 == 0) {
      EXPECT_EQ(block, nullptr) << i;
    } else {
      ASSERT_NE(block, nullptr) << i;
      EXPECT_EQ(block->index, GridIndex(i, -i, i % 7));
      EXPECT_EQ(block->voxels[i % TsdfBlock::kVoxels].weight, static_cast<float>(i + 1));
    }
  }
  std::vector<GridIndex> rest;
  for (const TsdfBlock* b : volume.blocks())
    rest.push_back(b->index);
  volume.removeBlocks(rest);
  EXPECT_EQ(volume.numBlocks(), 0u);
  volume.allocateBlock(GridIndex(1, 2, 3)); // still usable
  EXPECT_EQ(volume.numBlocks(), 1u);
}

TEST(StreamingMap, StreamedMeshIsTheInMemoryMeshWithNoSeams) {
  const double length = 60.0;
  const auto poses = drive(length, 0.5);
  const DriveResult memory = integrateDrive(poses, length);
  test::TempDir dir;
  const DriveResult streamed = integrateDrive(poses, length, dir.path(), minimumRadius() + 0.2);
  EXPECT_GT(streamed.stats.blocks_freed, 0u);
  EXPECT_GT(streamed.stats.tiles_written, 10u);
  EXPECT_EQ(streamed.stats.tiles_reloaded, 0u);
  EXPECT_LT(streamed.peak_blocks * 2, memory.peak_blocks) << streamed.peak_blocks << " of " << memory.peak_blocks;
  ASSERT_GT(memory.mesh.triangles.size(), 1000u);
  EXPECT_EQ(streamed.mesh.triangles.size(), memory.mesh.triangles.size());
  EXPECT_TRUE(triangleSet(streamed.mesh) == triangleSet(memory.mesh));
  // mesh.ply as written is one surface: the only open edges are the in-memory mesh's.
  expectWelded(streamed.mesh, memory.mesh);
  EXPECT_GT(openEdgesByIndex(memory.mesh), 0u);
  // Tiles were written while the drive went on, each a readable PLY.
  std::size_t tiles = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path() + "/tiles")) {
    TriangleMesh tile;
    StreamingMap::readMesh(entry.path().string(), tile);
    EXPECT_GT(tile.triangles.size(), 0u);
    ++tiles;
  }
  EXPECT_GT(tiles, 10u);
}

TEST(StreamingMap, StoreReloadsAndMeshesAgainToTheSameMesh) {
  const double length = 20.0;
  const auto poses = drive(length, 0.5);
  const DriveResult memory = integrateDrive(poses, length);
  test::TempDir dir;
  integrateDrive(poses, length, dir.path(), minimumRadius() + 0.2);
  MarchingCubes::Config mesher;
  mesher.min_weight = 0.f;
  mesher.min_component_triangles = 0; // a streamed map keeps its small pieces: compared alike
  // Tile by tile from the block files.
  EXPECT_EQ(StreamingMap::remesh(dir.path(), mesher, dir.file("remesh.ply")), memory.mesh.triangles.size());
  TriangleMesh remeshed;
  StreamingMap::readMesh(dir.file("remesh.ply"), remeshed);
  EXPECT_TRUE(triangleSet(remeshed) == triangleSet(memory.mesh));
  expectWelded(remeshed, memory.mesh);
  // The whole store as one volume.
  const TsdfVolume volume = StreamingMap::loadStore(dir.path());
  TriangleMesh whole;
  MarchingCubes(mesher).extract(volume, whole);
  EXPECT_TRUE(triangleSet(whole) == triangleSet(memory.mesh));
  // A region: fewer triangles, all of them the whole mesh's.
  const std::size_t part = StreamingMap::remesh(dir.path(), mesher, dir.file("part.ply"), Eigen::Vector3d(-10, -10, 0),
                                                Eigen::Vector3d(10, 10, 6));
  EXPECT_GT(part, 0u);
  EXPECT_LT(part, memory.mesh.triangles.size());
}

TEST(StreamingMap, AStoreTileNoWriterMakesIsRefusedNamingTheBlock) {
  const double length = 10.0;
  test::TempDir dir;
  integrateDrive(drive(length, 0.5), length, dir.path(), minimumRadius() + 0.2);
  const TsdfStore store = TsdfStore::open(dir.path());
  const auto bytesOf = [](const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  // The tile of the most blocks (a file at least two blocks long).
  const auto fuller = [&](const GridIndex& a, const GridIndex& b) {
    return bytesOf(store.blockPath(a)).size() < bytesOf(store.blockPath(b)).size();
  };
  const GridIndex tile = *std::max_element(store.tiles().begin(), store.tiles().end(), fuller);
  const std::string path = store.blockPath(tile);
  const std::string written = bytesOf(path);
  std::int32_t count = 0;
  std::memcpy(&count, written.data() + 28, sizeof(count));
  ASSERT_GE(count, 2);
  // The file: a 32-byte header, then per block its index (3 x int32), 4 bytes of sign bits
  // and 512 voxels of 12 bytes (sdf, weight, r, g, b, flags).
  const std::size_t header = 32, block = 16 + 512 * 12, first_voxel = header + 16;
  const auto put = [](std::string bytes, std::size_t at, auto value) {
    std::memcpy(&bytes[at], &value, sizeof(value));
    return bytes;
  };
  const std::int32_t outside = (tile.x() + 1) * store.tileBlocks(); // the first block's x in the next tile
  std::int32_t first[3];
  std::memcpy(first, written.data() + header, sizeof(first));
  const std::string first_name = TsdfStore::tileName(GridIndex(first[0], first[1], first[2]));
  const std::string file = "TSDF blocks '" + path + "'";
  const auto sizeError = [&](std::size_t size) {
    return file + " declare " + std::to_string(count) + " blocks, " + std::to_string(written.size()) +
           " bytes, but the file has " + std::to_string(size);
  };
  const auto at = [&](int block_number, const std::string& what) {
    return file + ": block " + std::to_string(block_number) + " of " + std::to_string(count) + " has " + what;
  };
  const std::string truncation = ", not within the truncation 0.5 m";
  const std::string second_as_first =
      written.substr(0, header + block) + written.substr(header, 12) + written.substr(header + block + 12);
  const std::vector<std::pair<std::string, std::string>> cases{
      {written.substr(0, written.size() - 1), sizeError(written.size() - 1)},
      {written + '\0', sizeError(written.size() + 1)},
      {put(written, first_voxel, std::nanf("")), at(1, "voxel 0 of sdf nan" + truncation)},
      {put(written, first_voxel, 0.75f), at(1, "voxel 0 of sdf 0.75" + truncation)},
      {put(written, first_voxel + 4, -1.f), at(1, "voxel 0 of weight -1, not a finite value >= 0")},
      {put(written, first_voxel + 11, std::uint8_t{0x41}),
       at(1, "voxel 0 of flags 65, bits other than the passes' and reappeared's")},
      {put(written, header, outside), at(1, "index " + std::to_string(outside) + "_" + std::to_string(first[1]) + "_" +
                                             std::to_string(first[2]) + ", outside tile " + TsdfStore::tileName(tile))},
      {second_as_first, at(2, "index " + first_name + ", as an earlier block has")},
  };
  for (const auto& [bytes, message] : cases) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    const std::string e = test::errorOf([&] { StreamingMap::loadStore(dir.path()); });
    EXPECT_EQ(e.substr(0, message.size()), message) << e;
    EXPECT_THROW(StreamingMap::remesh(dir.path(), MarchingCubes::Config(), dir.file("m.ply")), IOError);
    EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << written;
  EXPECT_NO_THROW(StreamingMap::loadStore(dir.path()));
}

TEST(StreamingMap, AStoreIndexWhoseTilesNoStreamingMapMakesIsRefused) {
  // A tile edge beyond the configuration's range: one tile's bookkeeping would not fit memory.
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("tsdf"));
  const std::string index = dir.file("tsdf/index.txt");
  for (const int tile_blocks : {0, TsdfStore::kMaxTileBlocks + 1, 100000}) {
    std::ofstream(index) << "msfusion-tsdf-store 1\nvoxel_size_m 0.1\ntruncation_m 0.3\nblock_side 8\ntile_blocks "
                         << tile_blocks << "\ntiles 1\n0 0 0\n";
    const std::string e = test::errorOf([&] { StreamingMap::loadStore(dir.path()); });
    EXPECT_EQ(e, "TSDF store index '" + index + "' has tile_blocks " + std::to_string(tile_blocks) + ", outside 1.." +
                     std::to_string(TsdfStore::kMaxTileBlocks));
    EXPECT_THROW(StreamingMap::remesh(dir.path(), MarchingCubes::Config(), dir.file("m.ply")), IOError);
    EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
  }
}

TEST(StreamingMap, AStoreIndexListingATileTwiceIsRefused) {
  // Meshed twice, every triangle of the tile was doubled.
  const double length = 10.0;
  test::TempDir dir;
  integrateDrive(drive(length, 0.5), length, dir.path(), minimumRadius() + 0.2);
  const std::string index = dir.path() + "/tsdf/index.txt";
  std::ifstream in(index);
  std::string text, line, first_tile;
  std::size_t tiles = 0;
  while (std::getline(in, line)) {
    if (line.rfind("tiles ", 0) == 0) {
      tiles = std::stoul(line.substr(6));
      line = "tiles " + std::to_string(tiles + 1);
    } else if (tiles > 0 && first_tile.empty()) {
      first_tile = line;
    }
    text += line + "\n";
  }
  in.close();
  ASSERT_GT(tiles, 1u);
  std::ofstream(index) << text << first_tile << "\n";
  std::istringstream xyz(first_tile);
  int x = 0, y = 0, z = 0;
  xyz >> x >> y >> z;
  const std::string e = test::errorOf([&] { StreamingMap::loadStore(dir.path()); });
  EXPECT_EQ(e, "TSDF store index '" + index + "' lists tile " + std::to_string(x) + "_" + std::to_string(y) + "_" +
                   std::to_string(z) + " twice (tiles 1 and " + std::to_string(tiles + 1) + ")");
  EXPECT_THROW(StreamingMap::remesh(dir.path(), MarchingCubes::Config(), dir.file("m.ply")), IOError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
}

TEST(StreamingMap, ALoopBackIntoStreamedSpaceReadsItBackAndDoublesNoSurface) {
  // Back to 25 m: the tiles near the turn are read back and written again, and the tiles
  // before them, on disk, are meshed again at the end (their cubes read the blocks read back).
  const double length = 40.0;
  const auto poses = drive(length, 0.5, 25.0);
  const DriveResult memory = integrateDrive(poses, length);
  test::TempDir dir;
  const DriveResult streamed = integrateDrive(poses, length, dir.path(), minimumRadius() + 0.2);
  EXPECT_GT(streamed.stats.tiles_reloaded, 0u);
  EXPECT_GT(streamed.stats.blocks_reloaded, 0u);
  EXPECT_GT(streamed.stats.tiles_remeshed, 0u);
  EXPECT_EQ(streamed.mesh.triangles.size(), memory.mesh.triangles.size());
  EXPECT_TRUE(triangleSet(streamed.mesh) == triangleSet(memory.mesh));
  expectWelded(streamed.mesh, memory.mesh);
}

TEST(StreamingMap, ALoopPastSurfacesAtTheCornersOfTheViewIsTheInMemoryMesh) {
  // A wide camera (127 degrees across) in a wide corridor: the walls and boxes near the edges
  // of the view, at up to 8 m depth, are 12-15 m from the camera. Driving back, the integrator
  // reaches tiles on disk there. With a reach of max_depth_m + truncation + 2 m (10.5 m, what
  // the pipeline told the map before the reach was the integrator's) and no reading back on
  // allocation, the bands started blocks afresh in tiles still on disk, whose stored blocks
  // were then dropped when the tiles were read back: 155 943 triangles against 157 078.
  const double length = 40.0;
  const auto poses = drive(length, 0.5, 5.0);
  Corridor setup;
  setup.wall = 12.0;
  setup.focal = 16.0;
  const DriveResult memory = integrateDrive(poses, length, "", 0.0, setup);
  ASSERT_GT(memory.mesh.triangles.size(), 1000u);
  const double radius = minimumRadius(setup) + 0.2; // 29 m
  for (const double reach : {0.0, kMaxDepth + kTruncation + 2.0}) {
    SCOPED_TRACE(reach > 0.0 ? "reach 10.5 m" : "the integrator's reach");
    setup.reach = reach;
    test::TempDir dir;
    const DriveResult streamed = integrateDrive(poses, length, dir.path(), radius, setup);
    EXPECT_GT(streamed.stats.tiles_reloaded, 0u);
    // Told too small a reach, the map reads tiles back when the integrator allocates blocks
    // in them (here that suffices: carving reaches no stored block beyond 10.5 m).
    if (reach > 0.0)
      EXPECT_GT(streamed.stats.tiles_reloaded_on_allocation, 0u);
    else
      EXPECT_EQ(streamed.stats.tiles_reloaded_on_allocation, 0u);
    EXPECT_EQ(streamed.mesh.triangles.size(), memory.mesh.triangles.size());
    EXPECT_TRUE(triangleSet(streamed.mesh) == triangleSet(memory.mesh));
    expectWelded(streamed.mesh, memory.mesh);
  }
}

TEST(TsdfIntegratorReach, IsTheFarthestCornerOfTheViewAtMaxDepthAndTwiceTheBandBehind) {
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.max_depth_m = 40.0;
  config.precise_max_depth_m = 0.0; // below: the precise depth's reach
  config.truncation_sigmas = 0.0;
  config.signed_distance = TsdfIntegrator::SignedDistance::Projective;
  PinholeCamera camera = test::centredCamera(201, 101, 100.0); // corners at (1.005, 0.505) per metre of depth
  const double corner = std::sqrt(1.0 + 1.005 * 1.005 + 0.505 * 0.505);
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(camera), (40.0 + 2 * 0.3) * corner, 1e-9);
  camera.cx = 0.f; // the far corner is now (200.5, 50.5) px off the centre
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(camera),
              (40.0 + 2 * 0.3) * std::sqrt(1.0 + 2.005 * 2.005 + 0.505 * 0.505), 1e-9);
  // The band grows with the depth's sigma, up to that of the least weight integrated.
  config.truncation_sigmas = 2.0;
  config.min_pixel_weight = 0.25f;
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(test::centredCamera(201, 101, 100.0)),
              (40.0 + 2 * 4.0) * corner, 1e-9);
  config.min_pixel_weight = 0.f;
  EXPECT_FALSE(std::isfinite(TsdfIntegrator(volume, config).reach(camera)));
  // A plane's band behind it: a voxel and a half over the least scale.
  config.truncation_sigmas = 0.0;
  config.signed_distance = TsdfIntegrator::SignedDistance::Plane;
  config.plane.min_scale = 0.05f;
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(test::centredCamera(201, 101, 100.0)),
              (40.0 + 2 * 0.15f / 0.05f) * corner, 1e-5);
  // Depth known to within the truncation goes on to precise_max_depth_m with per-pixel weights
  // (the default weighting) only.
  config.precise_max_depth_m = 60.0;
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(test::centredCamera(201, 101, 100.0)),
              (60.0 + 2 * 0.15f / 0.05f) * corner, 1e-5);
  config.weighting = TsdfIntegrator::Weighting::Constant;
  EXPECT_NEAR(TsdfIntegrator(volume, config).reach(test::centredCamera(201, 101, 100.0)),
              (40.0 + 2 * 0.15f / 0.05f) * corner, 1e-5);
}

TEST(StreamingMap, MemoryStaysBoundedOnALongDrive) {
  const double length = 240.0;
  const auto poses = drive(length, 0.6);
  test::TempDir dir;
  const DriveResult streamed = integrateDrive(poses, length, dir.path(), minimumRadius() + 0.2);
  const std::size_t n = streamed.blocks.size();
  const auto peak = [&](std::size_t a, std::size_t b) {
    return *std::max_element(streamed.blocks.begin() + static_cast<long>(a), streamed.blocks.begin() + static_cast<long>(b));
  };
  const std::size_t early = peak(n / 10, n / 5), late = peak(9 * n / 10, n);
  EXPECT_LE(late, early + early / 10) << "early " << early << " late " << late;
  EXPECT_GT(streamed.stats.blocks_freed, 5 * early);
}

TEST(StreamingMap, BadRadiusAndBadStoreAreClearErrors) {
  TsdfVolume volume(kVoxel, kTruncation);
  StreamingMap::Config config;
  config.active_radius_m = 5.0;
  test::TempDir dir;
  try {
    StreamingMap map(volume, config, MarchingCubes::Config(), 10.0, dir.path());
    FAIL() << "a radius below the reach was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("active_radius_m"), std::string::npos) << e.what();
  }
  config.active_radius_m = -1;
  EXPECT_THROW(config.validate(), ConfigError);
  EXPECT_THROW(StreamingMap::remesh(dir.path(), MarchingCubes::Config(), dir.file("m.ply")), IOError);
  std::filesystem::create_directories(dir.path() + "/tsdf");
  std::ofstream(dir.path() + "/tsdf/index.txt") << "something else\n";
  EXPECT_THROW(StreamingMap::loadStore(dir.path()), IOError);
  std::ofstream(dir.file("bad.ply")) << "ply\nformat ascii 1.0\n";
  TriangleMesh mesh;
  EXPECT_THROW(StreamingMap::readMesh(dir.file("bad.ply"), mesh), IOError);
}
