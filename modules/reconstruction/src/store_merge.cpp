// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/elapsed.h>
#include <msf/common/exceptions.h>
#include <msf/common/grid_key.h>
#include <msf/reconstruction/store_merge.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <memory>
#include <tuple>
#include <unordered_map>

namespace msf {

namespace {

using Clock = std::chrono::steady_clock;

/// A block of the merged tile: the first store's copy, and the weighted sums once a second
/// store holds it (in double, so that the mean of a few drives is rounded once, to float).
struct MergedBlock {
  struct Sums {
    double sdf_w = 0, w = 0, r_w = 0, g_w = 0, b_w = 0;
    int observers = 0, passes = TsdfVoxel::kMaxPasses;
    bool reappeared = false;
  };
  TsdfBlock block;
  std::unique_ptr<std::array<Sums, TsdfBlock::kVoxels>> sums;
  int holders = 0;

  void add(const TsdfBlock& b) {
    if (holders++ == 0) {
      block = b;
      return;
    }
    if (!sums) {
      sums = std::make_unique<std::array<Sums, TsdfBlock::kVoxels>>();
      accumulate(block);
    }
    accumulate(b);
    // A bit stays set where any store's voxels had that sign: a mean lies between its terms.
    block.signs |= b.signs;
    block.negative_subblocks |= b.negative_subblocks;
  }

  void accumulate(const TsdfBlock& b) {
    for (int i = 0; i < TsdfBlock::kVoxels; ++i) {
      const TsdfVoxel& v = b.voxels[i];
      if (!(v.weight > 0.f))
        continue;
      Sums& s = (*sums)[i];
      const double w = v.weight;
      s.sdf_w += static_cast<double>(v.sdf) * w;
      s.w += w;
      s.r_w += v.r * w;
      s.g_w += v.g * w;
      s.b_w += v.b * w;
      ++s.observers;
      s.passes = std::min(s.passes, v.passes());
      s.reappeared |= v.reappeared();
    }
  }

  /// The weighted means into `block`; counts the voxels several stores observed.
  void finish(float truncation, float max_weight, StoreMerge::Stats& stats) {
    if (!sums)
      return;
    for (int i = 0; i < TsdfBlock::kVoxels; ++i) {
      const Sums& s = (*sums)[i];
      TsdfVoxel& v = block.voxels[i];
      if (!(s.w > 0))
        continue;
      // A voxel one store observed keeps its values (its integrator capped its weight).
      const bool shared = s.observers > 1;
      stats.voxels_shared += shared ? 1 : 0;
      stats.voxels_capped += shared && s.w > max_weight ? 1 : 0;
      v.sdf = std::clamp(static_cast<float>(s.sdf_w / s.w), -truncation, truncation);
      v.weight = static_cast<float>(shared ? std::min(s.w, static_cast<double>(max_weight)) : s.w);
      v.r = static_cast<std::uint8_t>(s.r_w / s.w + 0.5);
      v.g = static_cast<std::uint8_t>(s.g_w / s.w + 0.5);
      v.b = static_cast<std::uint8_t>(s.b_w / s.w + 0.5);
      // Drives have no order: the passes every drive's latest rays made, and a surface that
      // reappeared in any drive.
      v.flags = static_cast<std::uint8_t>(s.passes << TsdfVoxel::kPassesShift |
                                          (s.reappeared ? TsdfVoxel::kReappeared : 0));
    }
    sums.reset();
  }
};

std::uint64_t blockKey(const GridIndex& b) { return GridKey<21>::pack(b); }

} // namespace

StoreMerge::Stats& StoreMerge::Stats::operator+=(const Stats& o) {
  tiles += o.tiles;
  tiles_shared += o.tiles_shared;
  blocks += o.blocks;
  blocks_shared += o.blocks_shared;
  voxels_shared += o.voxels_shared;
  voxels_capped += o.voxels_capped;
  ms += o.ms;
  return *this;
}

StoreMerge::StoreMerge(const std::vector<std::string>& stores, const Config& config) : config_(config) {
  if (stores.empty())
    throw InvalidInputError("a merge needs at least one TSDF store");
  if (!(config_.max_weight > 0.f))
    throw InvalidInputError("the merge's max_weight must be > 0, got " + std::to_string(config_.max_weight));
  for (const std::string& dir : stores) {
    stores_.push_back(TsdfStore::open(dir));
    const TsdfStore& s = stores_.back();
    if (!s.sameGrid(stores_.front()))
      throw InvalidInputError("TSDF stores '" + stores_.front().directory() + "' and '" + dir +
                              "' are on different grids (voxel size " + std::to_string(stores_.front().voxelSize()) +
                              " and " + std::to_string(s.voxelSize()) + " m, truncation " +
                              std::to_string(stores_.front().truncation()) + " and " + std::to_string(s.truncation()) +
                              " m, tiles of " + std::to_string(stores_.front().tileBlocks()) + " and " +
                              std::to_string(s.tileBlocks()) + " blocks): maps merge on one grid only");
    for (const GridIndex& t : s.tiles())
      holders_[t].push_back(static_cast<int>(stores_.size() - 1));
  }
  for (const auto& [tile, holders] : holders_)
    tiles_.push_back(tile);
}

StoreMerge::StoreMerge(const std::vector<std::string>& stores) : StoreMerge(stores, Config()) {}

const std::vector<int>& StoreMerge::storesOf(const GridIndex& tile) const {
  static const std::vector<int> none;
  const auto it = holders_.find(tile);
  return it == holders_.end() ? none : it->second;
}

std::vector<GridIndex> StoreMerge::tilesOfTask(int task, int tasks) const {
  if (tasks < 1 || task < 0 || task >= tasks)
    throw InvalidInputError("merge task " + std::to_string(task) + " of " + std::to_string(tasks) +
                            ": a task is 0.." + std::to_string(tasks - 1) + " of at least one");
  const std::size_t n = tiles_.size(), k = static_cast<std::size_t>(task), m = static_cast<std::size_t>(tasks);
  return {tiles_.begin() + static_cast<std::ptrdiff_t>(n * k / m),
          tiles_.begin() + static_cast<std::ptrdiff_t>(n * (k + 1) / m)};
}

TsdfStore StoreMerge::outputStore(const std::string& directory) const {
  const TsdfStore& grid = stores_.front();
  return TsdfStore(directory, grid.voxelSize(), grid.truncation(), grid.tileBlocks());
}

std::vector<TsdfBlock> StoreMerge::mergeTile(const GridIndex& tile, Stats* stats) const {
  Stats local;
  std::unordered_map<std::uint64_t, MergedBlock> blocks;
  const std::vector<int>& holders = storesOf(tile);
  for (const int s : holders)
    stores_[static_cast<std::size_t>(s)].readTile(tile, [&](const TsdfBlock& b) { blocks[blockKey(b.index)].add(b); });
  const float truncation = static_cast<float>(stores_.front().truncation());
  std::vector<TsdfBlock> merged;
  merged.reserve(blocks.size());
  for (auto& [key, m] : blocks) {
    local.blocks_shared += m.holders > 1 ? 1 : 0;
    m.finish(truncation, config_.max_weight, local);
    merged.push_back(m.block);
  }
  std::sort(merged.begin(), merged.end(), [](const TsdfBlock& a, const TsdfBlock& b) {
    return std::tie(a.index.z(), a.index.y(), a.index.x()) < std::tie(b.index.z(), b.index.y(), b.index.x());
  });
  local.tiles = 1;
  local.tiles_shared = holders.size() > 1 ? 1 : 0;
  local.blocks = merged.size();
  if (stats)
    *stats += local;
  return merged;
}

StoreMerge::Stats StoreMerge::merge(const std::vector<GridIndex>& tiles, const TsdfStore& out) const {
  const auto start = Clock::now();
  std::error_code e;
  std::filesystem::create_directories(std::filesystem::path(out.directory()) / "tsdf", e);
  Stats stats;
  for (const GridIndex& tile : tiles) {
    const std::vector<TsdfBlock> blocks = mergeTile(tile, &stats);
    std::vector<const TsdfBlock*> pointers;
    pointers.reserve(blocks.size());
    for (const TsdfBlock& b : blocks)
      pointers.push_back(&b);
    out.writeTile(tile, pointers);
  }
  stats.ms = msSince(start);
  return stats;
}

void StoreMerge::writeIndex(TsdfStore& out) const {
  for (const GridIndex& tile : tiles_)
    if (!std::filesystem::is_regular_file(out.blockPath(tile)))
      throw IOError("merged store '" + out.directory() + "' lacks tile " + TsdfStore::tileName(tile) + " ('" +
                    out.blockPath(tile) + "'): a merge task has not finished");
  out.writeIndex(tiles_);
}

} // namespace msf
