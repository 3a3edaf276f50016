// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/io/compressed_pcd.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <opencv2/core/utility.hpp>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <new>
#include <sstream>
#include <string>
#include <vector>

using namespace msf;

TEST(TsdfVolume, RejectsNonPositiveSizes) {
  EXPECT_THROW(TsdfVolume(0.0, 0.3), ConfigError);
  EXPECT_THROW(TsdfVolume(-0.1, 0.3), ConfigError);
  EXPECT_THROW(TsdfVolume(0.1, 0.0), ConfigError);
  try {
    TsdfVolume(0.0, 0.3);
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("voxel size"), std::string::npos) << e.what();
  }
}

TEST(TsdfVolume, BlocksAreSparseAndBoundless) {
  TsdfVolume volume(0.1, 0.3);
  EXPECT_EQ(volume.numBlocks(), 0u);
  EXPECT_EQ(volume.findBlock(GridIndex(0, 0, 0)), nullptr);
  TsdfBlock& far = volume.allocateBlock(GridIndex(-100000, 3, 250000));
  EXPECT_EQ(&far, volume.findBlock(GridIndex(-100000, 3, 250000)));
  EXPECT_EQ(&far, &volume.allocateBlock(GridIndex(-100000, 3, 250000)));
  EXPECT_EQ(volume.numBlocks(), 1u);
  EXPECT_GE(volume.memoryBytes(), sizeof(TsdfBlock));
  volume.allocateBlock(GridIndex(1, 1, 1));
  EXPECT_GE(volume.memoryBytes(), 2 * sizeof(TsdfBlock));
  // Voxel -1 is in block -1, voxel -8 too, -9 in block -2.
  EXPECT_EQ(blockOf(GridIndex(-1, 0, 7)), GridIndex(-1, 0, 0));
  EXPECT_EQ(blockOf(GridIndex(-8, 8, -9)), GridIndex(-1, 1, -2));
  EXPECT_EQ(volume.voxelIndexOf(Eigen::Vector3d(-0.149, 0.151, 0.04)), GridIndex(-1, 2, 0));
  EXPECT_EQ(volume.numObservedVoxels(), 0u);
}

TEST(TsdfVolume, BlocksKeepTheirAddressAndStartUnobservedAcrossStorageChunks) {
  TsdfVolume volume(0.1, 0.3);
  TsdfBlock* first = &volume.allocateBlock(GridIndex(0, 0, 0));
  first->at(1, 2, 3).weight = 5.f;
  std::vector<TsdfBlock*> seen;
  for (int i = 0; i < 1000; ++i) // blocks are stored ~340 to a 2 MiB chunk: several chunks
    seen.push_back(&volume.allocateBlock(GridIndex(i, -i, 7)));
  EXPECT_EQ(volume.numBlocks(), 1001u);
  EXPECT_EQ(volume.findBlock(GridIndex(0, 0, 0)), first);
  EXPECT_FLOAT_EQ(first->at(1, 2, 3).weight, 5.f);
  EXPECT_GE(volume.memoryBytes(), volume.numBlocks() * sizeof(TsdfBlock));
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()); // no two blocks share storage
  for (int i = 0; i < 1000; ++i)
    ASSERT_EQ(volume.findBlock(GridIndex(i, -i, 7)), volume.blocks()[static_cast<std::size_t>(i) + 1]);

  // Storage freed by clear() and used again holds fresh, unobserved blocks.
  for (TsdfBlock* b : volume.blocks())
    for (TsdfVoxel& v : b->voxels)
      v.weight = 1.f;
  volume.clear();
  EXPECT_EQ(volume.numBlocks(), 0u);
  for (int i = 0; i < 1000; ++i)
    volume.allocateBlock(GridIndex(i, 0, 0));
  EXPECT_EQ(volume.numObservedVoxels(), 0u);
}

TEST(TsdfVolume, AllocatingManyBlocksAtOnceEqualsOneAtATime) {
  TsdfVolume one(0.1, 0.3), many(0.1, 0.3);
  std::vector<GridIndex> indices;
  for (int i = 0; i < 900; ++i)
    indices.emplace_back(i % 30, -(i / 30), i % 7);
  indices.push_back(indices[5]); // a repeated index gives the same block
  one.allocateBlock(indices[10]).at(0, 0, 0).weight = 2.f; // an existing block is kept
  many.allocateBlock(indices[10]).at(0, 0, 0).weight = 2.f;
  std::vector<TsdfBlock*> blocks;
  many.allocateBlocks(indices, blocks);
  for (const GridIndex& index : indices)
    one.allocateBlock(index);
  ASSERT_EQ(blocks.size(), indices.size());
  EXPECT_EQ(many.numBlocks(), one.numBlocks());
  EXPECT_EQ(blocks.back(), blocks[5]);
  EXPECT_FLOAT_EQ(blocks[10]->at(0, 0, 0).weight, 2.f);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    ASSERT_EQ(blocks[i], many.findBlock(indices[i]));
    ASSERT_EQ(blocks[i]->index, indices[i]);
    ASSERT_EQ(many.blocks()[i < 900 ? i : 5]->index, one.blocks()[i < 900 ? i : 5]->index); // the same order
  }
  EXPECT_EQ(many.numObservedVoxels(), 1u);
  EXPECT_GE(many.memoryBytes(), many.numBlocks() * sizeof(TsdfBlock));
}

namespace {

/// A sphere seen from ten poses on an arc, coloured (10, 120, 250) BGR.
TsdfVolume sphereVolume(double voxel_size, double truncation) {
  const AnalyticScene scene = test::makeScene(test::SceneKind::Sphere);
  TsdfVolume volume(voxel_size, truncation);
  TsdfIntegrator integrator(volume);
  const auto camera = test::smallCamera();
  for (const auto& pose : test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 10, 3)) {
    DepthFrame frame = test::renderFrame(scene, camera, pose);
    frame.color.create(frame.depth.size(), CV_8UC3);
    frame.color.setTo(cv::Scalar(10, 120, 250));
    integrator.integrate(frame, pose);
  }
  return volume;
}

} // namespace

TEST(TsdfVolume, SaveLoadRoundTripKeepsEveryVoxelAndTheMesh) {
  const TsdfVolume volume = sphereVolume(0.04, 0.12);
  ASSERT_GT(volume.numObservedVoxels(), 1000u);

  test::TempDir dir;
  volume.save(dir.file("volume.pcd"));
  const TsdfVolume loaded = TsdfVolume::load(dir.file("volume.pcd"));
  EXPECT_DOUBLE_EQ(loaded.voxelSize(), 0.04);
  EXPECT_DOUBLE_EQ(loaded.truncation(), 0.12);
  EXPECT_EQ(loaded.numObservedVoxels(), volume.numObservedVoxels());
  std::size_t compared = 0, passed = 0, reappeared = 0;
  for (const auto& block : volume.blocks())
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          const TsdfVoxel& a = block->at(x, y, z);
          if (!a.observed())
            continue;
          const TsdfVoxel* b = loaded.findVoxel(block->origin() + GridIndex(x, y, z));
          ASSERT_NE(b, nullptr);
          EXPECT_EQ(a.sdf, b->sdf);
          EXPECT_EQ(a.weight, b->weight);
          EXPECT_EQ(a.r, b->r);
          EXPECT_EQ(a.g, b->g);
          EXPECT_EQ(a.b, b->b);
          EXPECT_EQ(a.passes(), b->passes());
          EXPECT_EQ(a.reappeared(), b->reappeared());
          passed += a.passes() > 0;
          reappeared += a.reappeared();
          ++compared;
        }
  EXPECT_EQ(compared, volume.numObservedVoxels());
  EXPECT_GT(passed, 100u); // the free space in front of the sphere
  EXPECT_GT(reappeared, 10u); // its silhouette, passed from one side and seen from another
  const TsdfVoxel* some = nullptr;
  for (const auto& block : loaded.blocks())
    for (const auto& v : block->voxels)
      if (v.observed() && std::abs(v.sdf) < 0.01f)
        some = &v;
  ASSERT_NE(some, nullptr);
  EXPECT_EQ(some->r, 250);
  EXPECT_EQ(some->g, 120);
  EXPECT_EQ(some->b, 10);

  TriangleMesh a, b;
  MarchingCubes().extract(volume, a);
  MarchingCubes().extract(loaded, b);
  ASSERT_GT(a.triangles.size(), 100u);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);

  // The file is a PCD that PCL reads as a cloud with the named fields.
  pcl::PointCloud<PointTsdf> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(dir.file("volume.pcd"), cloud), 0);
  EXPECT_EQ(cloud.size(), volume.numObservedVoxels());
}

TEST(TsdfVolume, TheFileSavedFromTheBlocksIsTheCloudOfToCloudByteForByte) {
  // save() writes the voxels' values straight from the blocks; the file is the one of
  // toCloud's cloud, over several pieces of the compressed body, on any number of threads.
  const TsdfVolume volume = sphereVolume(0.02, 0.06);
  ASSERT_GT(volume.numObservedVoxels() * 26, 3u << 20) << "fewer than three pieces of 1 MiB";
  test::TempDir dir;
  volume.save(dir.file("all.pcd"));
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  volume.save(dir.file("one.pcd"));
  cv::setNumThreads(threads);
  const auto bytes = [](const std::string& path) {
    std::ostringstream text;
    text << std::ifstream(path, std::ios::binary).rdbuf();
    return text.str();
  };
  const std::string saved = bytes(dir.file("all.pcd"));
  EXPECT_TRUE(saved == bytes(dir.file("one.pcd")));

  pcl::PointCloud<PointTsdf> cloud;
  volume.toCloud(cloud);
  const std::size_t comment = saved.find('\n') + 1; // the volume's parameters
  std::ostringstream expected;
  writeCompressedPcd(expected, cloud, saved.substr(comment, saved.find('\n', comment) + 1 - comment));
  EXPECT_EQ(saved.size(), expected.str().size());
  EXPECT_TRUE(saved == expected.str()) << "save() and toCloud() differ";
}

namespace {

struct VoxelValues {
  float sdf, weight;
  int r, b, passes;
  bool reappeared;
};

void expectVoxel(const TsdfVoxel& v, const VoxelValues& e, const char* what) {
  EXPECT_FLOAT_EQ(v.sdf, e.sdf) << what;
  EXPECT_FLOAT_EQ(v.weight, e.weight) << what;
  EXPECT_EQ(v.r, e.r) << what;
  EXPECT_EQ(v.b, e.b) << what;
  EXPECT_EQ(v.passes(), e.passes) << what;
  EXPECT_EQ(v.reappeared(), e.reappeared) << what;
}

} // namespace

TEST(TsdfVolume, AVolumeFileLoadsWhateverItsFieldsOrderTypesOrAge) {
  test::TempDir dir;
  // Two voxels of an ASCII volume of 0.1 m voxels: the voxel at the origin and `second`'s.
  const auto load = [&](const std::string& name, const std::string& fields_to_points, const GridIndex& second) {
    std::ofstream(dir.file(name)) << "# .PCD v0.7 - Point Cloud Data file format\n"
                                     "# msfusion tsdf voxel_size_m 0.1 truncation_m 0.3\nVERSION 0.7\n"
                                  << fields_to_points;
    const TsdfVolume volume = TsdfVolume::load(dir.file(name));
    EXPECT_EQ(volume.numObservedVoxels(), 2u) << name;
    const TsdfVoxel *a = volume.findVoxel(GridIndex(0, 0, 0)), *b = volume.findVoxel(second);
    return std::make_pair(a ? *a : TsdfVoxel(), b ? *b : TsdfVoxel());
  };
  struct Case {
    const char* name;
    std::string fields_to_points;
    GridIndex second;
    VoxelValues first_values, second_values;
  };
  const Case cases[] = {
      // Saved before the passes and reappeared fields: their voxels load, none passed.
      {"older.pcd",
       "FIELDS x y z sdf weight rgb\nSIZE 4 4 4 4 4 4\nTYPE F F F F F U\nCOUNT 1 1 1 1 1 1\n"
       "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
       "0 0 0 -0.05 10 4278190335\n0.1 0 0 0.05 12 4278190335\n",
       GridIndex(1, 0, 0), {-0.05f, 10.f, 0, 255, 0, false}, {0.05f, 12.f, 0, 255, 0, false}},
      // Fields read where the file has them: another order, rgba for rgb, a float64 x y z.
      {"reordered.pcd",
       "FIELDS weight rgba reappeared x y z passes sdf\nSIZE 4 4 1 8 8 8 1 4\nTYPE F U U F F F U F\n"
       "COUNT 1 1 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
       "10 4278190335 0 0 0 0 2 -0.05\n12 4294901760 1 0.1 0 0.8 1 0.05\n",
       GridIndex(1, 0, 8), {-0.05f, 10.f, 0, 255, 2, false}, {0.05f, 12.f, 255, 0, 1, true}},
  };
  for (const Case& c : cases) {
    const auto [first, second] = load(c.name, c.fields_to_points, c.second);
    expectVoxel(first, c.first_values, c.name);
    expectVoxel(second, c.second_values, c.name);
  }
}

namespace {

/// A volume .pcd of one voxel at the origin, with the uint8 fields `names` of `values` after rgb.
void writeOneVoxel(const std::string& path, const std::vector<std::string>& names, const std::vector<int>& values) {
  std::string fields, sizes, types, counts, row;
  for (std::size_t i = 0; i < names.size(); ++i) {
    fields += " " + names[i];
    sizes += " 1";
    types += " U";
    counts += " 1";
    row += " " + std::to_string(values[i]);
  }
  std::ofstream(path) << "# .PCD v0.7 - Point Cloud Data file format\n"
                         "# msfusion tsdf voxel_size_m 0.1 truncation_m 0.3\n"
                         "VERSION 0.7\nFIELDS x y z sdf weight rgb" << fields << "\nSIZE 4 4 4 4 4 4" << sizes
                      << "\nTYPE F F F F F U" << types << "\nCOUNT 1 1 1 1 1 1" << counts
                      << "\nWIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 0 -0.05 10 4278190335"
                      << row << "\n";
}

} // namespace

TEST(TsdfVolume, AVoxelWithMorePassesThanItCountsIsRefused) {
  test::TempDir dir;
  const auto write = [&](const std::string& name, int passes) { writeOneVoxel(dir.file(name), {"passes"}, {passes}); };
  write("three.pcd", TsdfVoxel::kMaxPasses);
  EXPECT_EQ(TsdfVolume::load(dir.file("three.pcd")).findVoxel(GridIndex(0, 0, 0))->passes(), TsdfVoxel::kMaxPasses);
  write("nine.pcd", 9);
  const std::string error = test::errorOf([&] { TsdfVolume::load(dir.file("nine.pcd")); });
  EXPECT_NE(error.find("nine.pcd"), std::string::npos) << error;
  EXPECT_NE(error.find("voxel 0 has passes 9, more than the 3 a voxel counts"), std::string::npos) << error;
}

TEST(TsdfVolume, ReappearedIsLoadedAndAValueOtherThanZeroOrOneIsRefused) {
  test::TempDir dir;
  const auto write = [&](const std::string& name, int reappeared) {
    writeOneVoxel(dir.file(name), {"passes", "reappeared"}, {1, reappeared});
  };
  write("one.pcd", 1);
  const TsdfVolume one = TsdfVolume::load(dir.file("one.pcd"));
  EXPECT_TRUE(one.findVoxel(GridIndex(0, 0, 0))->reappeared());
  EXPECT_EQ(one.findVoxel(GridIndex(0, 0, 0))->passes(), 1);
  write("two.pcd", 2);
  const std::string error = test::errorOf([&] { TsdfVolume::load(dir.file("two.pcd")); });
  EXPECT_NE(error.find("two.pcd"), std::string::npos) << error;
  EXPECT_NE(error.find("voxel 0 has reappeared 2, not 0 or 1"), std::string::npos) << error;
}

TEST(PointTsdf, ADefaultPointIsAnUnobservedVoxelAtTheOrigin) {
  // Built over memory full of garbage, so that a field the constructor forgets keeps it.
  alignas(PointTsdf) unsigned char storage[sizeof(PointTsdf)];
  std::memset(storage, 0xAB, sizeof(storage));
  const PointTsdf* p = new (storage) PointTsdf;
  EXPECT_EQ(p->x, 0.f);
  EXPECT_EQ(p->y, 0.f);
  EXPECT_EQ(p->z, 0.f);
  EXPECT_EQ(p->sdf, 0.f);
  EXPECT_EQ(p->weight, 0.f);
  EXPECT_EQ(p->rgba, 0xFF000000u); // black, opaque
  EXPECT_EQ(p->passes, 0);
  EXPECT_EQ(p->reappeared, 0);
}

TEST(TsdfVolume, SaveAndLoadRejectBadFiles) {
  test::TempDir dir;
  TsdfVolume empty(0.1, 0.3);
  EXPECT_THROW(empty.save(dir.file("empty.pcd")), InvalidInputError);
  empty.allocateBlock(GridIndex(0, 0, 0)).at(1, 2, 3).weight = 1.f;
  EXPECT_THROW(empty.save(dir.file("volume.ply")), IOError);
  EXPECT_EQ(test::countEntries(dir.path()), 0u);
  EXPECT_THROW(empty.save(dir.path() + "/missing/volume.pcd"), IOError);

  try {
    TsdfVolume::load(dir.file("absent.pcd"));
    FAIL();
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.pcd"), std::string::npos) << e.what();
  }
  // A plain cloud without the volume's header comment: one default point (every field 0) given a weight.
  pcl::PointCloud<PointTsdf> cloud;
  cloud.resize(1);
  cloud[0].weight = 1.f;
  EXPECT_EQ(cloud[0].passes, 0);
  EXPECT_EQ(cloud[0].reappeared, 0);
  pcl::io::savePCDFileBinary(dir.file("plain.pcd"), cloud);
  try {
    TsdfVolume::load(dir.file("plain.pcd"));
    FAIL();
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("plain.pcd"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("voxel_size_m"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-voxel V -trunc T"), std::string::npos) << e.what();
  }
  // Given the voxel size and truncation the PCL rewrite dropped, it loads.
  const TsdfVolume given = TsdfVolume::load(dir.file("plain.pcd"), 0.1, 0.3);
  EXPECT_DOUBLE_EQ(given.voxelSize(), 0.1);
  EXPECT_DOUBLE_EQ(given.truncation(), 0.3);
  EXPECT_EQ(given.numObservedVoxels(), 1u);
  EXPECT_THROW(TsdfVolume::load(dir.file("plain.pcd"), 0.1, 0), IOError); // half of it is not enough
  // A cloud without the sdf field.
  empty.save(dir.file("one.pcd"));
  EXPECT_EQ(TsdfVolume::load(dir.file("one.pcd")).numObservedVoxels(), 1u);
  EXPECT_EQ(TsdfVolume::load(dir.file("one.pcd"), empty.voxelSize(), empty.truncation()).numObservedVoxels(), 1u);
  try { // values that contradict the file's own are an error, not a silent choice
    TsdfVolume::load(dir.file("one.pcd"), 2 * empty.voxelSize());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("was written with voxel_size_m"), std::string::npos) << e.what();
  }
  pcl::PointCloud<pcl::PointXYZ> xyz;
  xyz.push_back(pcl::PointXYZ(0, 0, 0));
  pcl::io::savePCDFileASCII(dir.file("xyz.pcd"), xyz);
  {
    std::ifstream in(dir.file("xyz.pcd"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.insert(text.find('\n') + 1, "# msfusion tsdf voxel_size_m 0.1 truncation_m 0.3\n");
    std::ofstream(dir.file("xyz.pcd")) << text;
  }
  try {
    TsdfVolume::load(dir.file("xyz.pcd"));
    FAIL();
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("sdf"), std::string::npos) << e.what();
  }
}
