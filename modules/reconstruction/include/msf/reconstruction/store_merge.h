// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/tsdf_store.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace msf {

/// Several TSDF stores of one world (drives whose poses share a frame, each streamed by
/// msf_reconstruct -stream) merged into one, tile by tile: a voxel that several stores
/// observed takes the TSDF's own weighted mean, its signed distance and colour averaged by
/// weight and the weights summed (capped as the integrator caps them); a voxel, block or tile
/// that one store alone holds is copied as it is. Where integration is a plain weighted mean
/// (no space carving, no weight cap reached, lambda 0) that is what integrating all the
/// drives' frames into one volume gives, to float rounding (docs/batch.md: by how much it
/// differs where integration is not).
///
/// Tiles are independent: tasks merge disjoint shares of them side by side (tilesOfTask) into
/// one output store, each tile file written atomically, so a task run again writes the same
/// files; writeIndex() lists them once all are written.
class StoreMerge {
public:
  struct Config {
    /// The integrator's cap (tsdf_integrator.max_weight): a merged weight is the sum, capped here.
    float max_weight = 1e4f;
  };

  struct Stats {
    std::size_t tiles = 0;          ///< tiles merged
    std::size_t tiles_shared = 0;   ///< of which more than one store holds
    std::size_t blocks = 0;         ///< blocks written
    std::size_t blocks_shared = 0;  ///< of which more than one store holds
    std::size_t voxels_shared = 0;  ///< voxels observed by more than one store
    std::size_t voxels_capped = 0;  ///< of which the summed weight exceeded max_weight
    double ms = 0;                  ///< reading, merging and writing
    Stats& operator+=(const Stats& o);
  };

  /// Opens the stores in `stores` (folders with tsdf/index.txt). Throws IOError naming a
  /// store whose index is missing or garbled, InvalidInputError naming two stores on different
  /// grids (voxel size, truncation, tile size) or when `stores` is empty.
  StoreMerge(const std::vector<std::string>& stores, const Config& config);
  /// With the default Config (the integrator's default cap).
  explicit StoreMerge(const std::vector<std::string>& stores);

  const Config& config() const { return config_; }
  const std::vector<TsdfStore>& stores() const { return stores_; }
  /// Every tile of any store, in the index's order.
  const std::vector<GridIndex>& tiles() const { return tiles_; }
  /// The stores (positions in stores()) that hold `tile`; empty for a tile of none.
  const std::vector<int>& storesOf(const GridIndex& tile) const;
  /// The share of task `task` of `tasks` (0 <= task < tasks): a run of consecutive tiles of
  /// tiles(), the runs of all tasks covering it once. Throws InvalidInputError for a task out of range.
  std::vector<GridIndex> tilesOfTask(int task, int tasks) const;

  /// A store on the stores' grid in `directory` (not yet written).
  TsdfStore outputStore(const std::string& directory) const;
  /// The merged blocks of `tile`, sorted by z, y, x (the streaming map's order).
  std::vector<TsdfBlock> mergeTile(const GridIndex& tile, Stats* stats = nullptr) const;
  /// Merges `tiles` and writes each into `out` (its tsdf/X_Y_Z.blk; not the index).
  Stats merge(const std::vector<GridIndex>& tiles, const TsdfStore& out) const;
  /// Lists every tile of tiles() in `out`'s index. Throws IOError naming the first tile whose
  /// block file is missing (a task that has not finished).
  void writeIndex(TsdfStore& out) const;

private:
  Config config_;
  std::vector<TsdfStore> stores_;
  std::vector<GridIndex> tiles_;
  std::map<GridIndex, std::vector<int>, decltype(&TsdfStore::tileOrder)> holders_{&TsdfStore::tileOrder};
};

} // namespace msf
