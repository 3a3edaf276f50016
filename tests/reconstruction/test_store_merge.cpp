// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "store_difference.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/store_merge.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <tuple>

using namespace msf;

namespace {

namespace fs = std::filesystem;

constexpr double kVoxel = 0.2, kTruncation = 0.5, kMaxDepth = 8.0;

/// Integration as a plain weighted mean: constant weights, no space carving, no cap reached,
/// lambda 0 (the default). What a merge equals.
TsdfIntegrator::Config plainMean() {
  TsdfIntegrator::Config config;
  config.max_depth_m = kMaxDepth;
  config.plane.min_scale = 0.25f;
  config.weighting = TsdfIntegrator::Weighting::Constant;
  config.space_carving = false;
  config.scan_carving_m = 0.0;
  config.max_weight = 1e30f;
  return config;
}

/// A drive along the corridor from z0 to z1 (reversed when z1 < z0), a pose a metre.
std::vector<Eigen::Isometry3d> drive(double z0, double z1) {
  std::vector<Eigen::Isometry3d> poses;
  const double step = z1 >= z0 ? 1.0 : -1.0;
  for (double z = z0; step * (z1 - z) >= 0; z += step)
    poses.push_back(test::lookAt(Eigen::Vector3d(0.3 * std::sin(z) - (step < 0 ? 1.0 : 0.0), 0.0, z),
                                 Eigen::Vector3d(0, 0.3, z + 10 * step)));
  return poses;
}

/// Integrates drives `which` of `drives` one after the other into one volume streamed to
/// `directory`: one drive makes a drive's store, all of them the one-process map. A frame's
/// noise and colour depend on its drive and place in it only, so both see the same frames.
void integrateInto(const std::vector<std::vector<Eigen::Isometry3d>>& drives, const std::vector<std::size_t>& which,
                   const std::string& directory) {
  const AnalyticScene scene = test::corridor(50);
  const PinholeCamera camera = test::centredCamera(64, 48, 40.0);
  TsdfVolume volume(kVoxel, kTruncation);
  TsdfIntegrator integrator(volume, plainMean());
  StreamingMap::Config streaming;
  streaming.active_radius_m = 100.0; // nothing leaves before the end: the store is the whole map
  streaming.tile_blocks = 2;
  MarchingCubes::Config mesher;
  mesher.min_component_triangles = 0;
  StreamingMap map(volume, streaming, mesher, integrator.reach(camera), directory);
  for (const std::size_t k : which)
    for (std::size_t i = 0; i < drives[k].size(); ++i) {
      const Eigen::Isometry3d& pose = drives[k][i];
      const unsigned frame = static_cast<unsigned>(100 * k + i + 1);
      DepthFrame depth = test::renderFrame(scene, camera, pose, 0.02, frame);
      depth.depth.setTo(0.f, depth.depth > kMaxDepth - 0.5);
      depth.color = cv::Mat(depth.depth.size(), CV_8UC3, cv::Scalar(frame * 7 % 256, 90, 200));
      map.beforeIntegration(pose.translation());
      integrator.integrate(depth, pose);
      map.afterIntegration(pose.translation());
    }
  map.finish(directory + "/mesh.ply");
}

class StoreMergeTest : public ::testing::Test {
protected:
  void SetUp() override {
    drives_ = {drive(0, 12), drive(6, 20), drive(26, 10)}; // overlapping, the third the other way
    for (std::size_t k = 0; k < drives_.size(); ++k) {
      stores_.push_back(dir_.file("drive" + std::to_string(k)));
      integrateInto(drives_, {k}, stores_.back());
    }
  }
  test::TempDir dir_;
  std::vector<std::vector<Eigen::Isometry3d>> drives_;
  std::vector<std::string> stores_;
};

TEST_F(StoreMergeTest, EqualsIntegratingEveryFrameInOneVolumeToFloatRounding) {
  integrateInto(drives_, {0, 1, 2}, dir_.file("one"));
  StoreMerge::Config config;
  config.max_weight = 1e30f;
  const StoreMerge merge(stores_, config);
  TsdfStore merged = merge.outputStore(dir_.file("merged"));
  const StoreMerge::Stats stats = merge.merge(merge.tiles(), merged);
  merge.writeIndex(merged);
  EXPECT_GT(stats.tiles_shared, 0u);
  EXPECT_GT(stats.voxels_shared, 1000u) << "the drives overlap";
  EXPECT_EQ(stats.voxels_capped, 0u);

  const TsdfStore one = TsdfStore::open(dir_.file("one"));
  EXPECT_EQ(TsdfStore::open(dir_.file("merged")).tiles(), one.tiles());
  const test::StoreDifference d = test::compareStores(TsdfStore::open(dir_.file("merged")), one);
  EXPECT_TRUE(d.same_blocks);
  EXPECT_GT(d.observed, 10000u);
  // A running mean in float against a mean of three means in double: rounding, ~1e-7 relative.
  EXPECT_LT(d.sdf, 1e-5 * kTruncation);
  EXPECT_LT(d.weight_relative, 1e-5);
  // Colour is not a plain mean: it is updated near the surface only while the weight counts
  // every update, so it depends on the order of a voxel's coloured and uncoloured updates (here
  // each frame has a colour of its own, the worst case).
  EXPECT_LT(d.colour_off, d.observed / 20) << "colour off by more than 2 grey levels, of " << d.observed;
  EXPECT_LT(d.colour_mean, 1.0) << d.colour;
}

TEST_F(StoreMergeTest, ABlockOfOneStoreIsCopiedBitForBit) {
  const StoreMerge merge(stores_);
  const test::BlockMap first = test::blocksOf(TsdfStore::open(stores_[0]));
  std::size_t alone = 0;
  for (const GridIndex& tile : merge.tiles()) {
    if (merge.storesOf(tile) != std::vector<int>{0})
      continue;
    for (const TsdfBlock& b : merge.mergeTile(tile)) {
      const TsdfBlock& original = first.at({b.index.x(), b.index.y(), b.index.z()});
      EXPECT_EQ(std::memcmp(b.voxels.data(), original.voxels.data(), sizeof b.voxels), 0);
      EXPECT_EQ(b.signs, original.signs);
      ++alone;
    }
  }
  EXPECT_GT(alone, 0u) << "the first drive has tiles of its own";
}

TEST_F(StoreMergeTest, SharedVoxelsTakeTheWeightedMeanAndTheCap) {
  StoreMerge::Config config;
  config.max_weight = 500.f; // a few observations of sigma 5 cm (400 m^-2 each)
  const StoreMerge merge(stores_, config);
  const std::vector<test::BlockMap> inputs = {test::blocksOf(TsdfStore::open(stores_[0])),
                                              test::blocksOf(TsdfStore::open(stores_[1])),
                                              test::blocksOf(TsdfStore::open(stores_[2]))};
  StoreMerge::Stats stats;
  std::size_t checked = 0, passed = 0, reappeared_shared = 0;
  for (const GridIndex& tile : merge.tiles())
    for (const TsdfBlock& b : merge.mergeTile(tile, &stats))
      for (int i = 0; i < TsdfBlock::kVoxels; i += 7) {
        double w = 0, sdf_w = 0;
        std::uint8_t signs = 0;
        int holders = 0, passes = TsdfVoxel::kMaxPasses;
        bool reappeared = false;
        for (const test::BlockMap& in : inputs)
          if (const auto it = in.find({b.index.x(), b.index.y(), b.index.z()}); it != in.end()) {
            const TsdfVoxel& v = it->second.voxels[i];
            w += v.weight;
            sdf_w += static_cast<double>(v.sdf) * v.weight;
            signs |= it->second.signs;
            ++holders;
            if (v.weight > 0) {
              passes = std::min(passes, v.passes());
              reappeared |= v.reappeared();
            }
          }
        EXPECT_EQ(b.signs, signs);
        if (!(w > 0) || holders < 2) // a block of one store is copied
          continue;
        EXPECT_FLOAT_EQ(b.voxels[i].sdf, static_cast<float>(sdf_w / w));
        // The passes every drive's latest rays made; a surface that reappeared in any drive.
        EXPECT_EQ(b.voxels[i].passes(), passes);
        EXPECT_EQ(b.voxels[i].reappeared(), reappeared);
        passed += passes > 0;
        reappeared_shared += reappeared;
        const bool shared = std::count_if(inputs.begin(), inputs.end(), [&](const test::BlockMap& in) {
                              const auto it = in.find({b.index.x(), b.index.y(), b.index.z()});
                              return it != in.end() && it->second.voxels[i].weight > 0;
                            }) > 1;
        EXPECT_FLOAT_EQ(b.voxels[i].weight, static_cast<float>(shared ? std::min(w, 500.0) : w));
        ++checked;
      }
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(passed, 10u);
  EXPECT_GT(reappeared_shared, 10u);
  EXPECT_GT(stats.voxels_capped, 0u);
  EXPECT_LE(stats.voxels_capped, stats.voxels_shared);
}

TEST_F(StoreMergeTest, TasksShareTheTilesOnceAndTheIndexWaitsForAll) {
  const StoreMerge merge(stores_);
  std::vector<GridIndex> all;
  for (int k = 0; k < 3; ++k)
    for (const GridIndex& t : merge.tilesOfTask(k, 3))
      all.push_back(t);
  EXPECT_EQ(all, merge.tiles());
  EXPECT_NE(test::errorOf([&] { merge.tilesOfTask(3, 3); }).find("task 3 of 3"), std::string::npos);

  // Two tasks of three: the index names a tile the third has not written.
  TsdfStore out = merge.outputStore(dir_.file("partial"));
  merge.merge(merge.tilesOfTask(0, 3), out);
  merge.merge(merge.tilesOfTask(2, 3), out);
  const std::string missing = TsdfStore::tileName(merge.tilesOfTask(1, 3).front());
  EXPECT_NE(test::errorOf([&] { merge.writeIndex(out); }).find("lacks tile " + missing), std::string::npos);
  // A task run again writes the same files.
  merge.merge(merge.tilesOfTask(1, 3), out);
  merge.merge(merge.tilesOfTask(1, 3), out);
  merge.writeIndex(out);
  EXPECT_EQ(TsdfStore::open(dir_.file("partial")).tiles(), merge.tiles());
}

TEST(StoreMerge, RefusesStoresOfOtherGridsAndMissingOnes) {
  test::TempDir dir;
  TsdfStore(dir.file("a"), 0.2, 0.5, 2).writeIndex({});
  TsdfStore(dir.file("b"), 0.1, 0.5, 2).writeIndex({});
  TsdfStore(dir.file("c"), 0.2, 0.5, 4).writeIndex({});
  EXPECT_NE(test::errorOf([&] { StoreMerge({dir.file("a"), dir.file("b")}); }).find("different grids"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { StoreMerge({dir.file("a"), dir.file("c")}); }).find("tiles of 2 and 4 blocks"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { StoreMerge({dir.file("a"), dir.file("none")}); }).find(dir.file("none")),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { StoreMerge({}); }).find("at least one"), std::string::npos);
}

} // namespace
