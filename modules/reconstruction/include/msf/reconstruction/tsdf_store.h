// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/tsdf_block.h>

#include <functional>
#include <string>
#include <vector>

namespace msf {

/// The TSDF of a map on disk, tile by tile (docs/streaming.md, "On-disk format"):
/// DIR/tsdf/index.txt names the grid (voxel size, truncation, tile size) and lists the tiles;
/// DIR/tsdf/X_Y_Z.blk holds a tile's blocks as the integrator left them (voxels and sign
/// bits). A StreamingMap writes one as the camera moves on; StoreMerge merges several into
/// one. Every file is written atomically (a temporary and a rename).
class TsdfStore {
public:
  /// The largest tile edge in blocks (streaming.tile_blocks): a tile of 64^3 blocks is 1.6 GB.
  static constexpr int kMaxTileBlocks = 64;

  /// A store in `directory` on the grid given (nothing is read or written yet).
  TsdfStore(std::string directory, double voxel_size_m, double truncation_m, int tile_blocks);
  /// The store in `directory`, from its index. Throws IOError naming the index when it is
  /// missing or not one a StreamingMap wrote (a tile_blocks outside 1..kMaxTileBlocks among them).
  static TsdfStore open(const std::string& directory);

  const std::string& directory() const { return directory_; }
  double voxelSize() const { return voxel_size_; }
  double truncation() const { return truncation_; }
  int tileBlocks() const { return tile_blocks_; }
  /// Edge of a tile in metres.
  double tileSizeM() const { return tile_blocks_ * TsdfBlock::kSide * voxel_size_; }
  /// The tiles of the index (as read by open(), or as last given to writeIndex()).
  const std::vector<GridIndex>& tiles() const { return tiles_; }
  /// Whether another store has the same grid (voxel size, truncation, tile size), to within
  /// float rounding of the values written.
  bool sameGrid(const TsdfStore& other) const;

  /// DIR/tsdf/X_Y_Z.blk
  std::string blockPath(const GridIndex& tile) const;
  /// Calls `add` with each block of tile `tile` (signs and voxels as written; stamp 0).
  /// Throws IOError naming the file, before any block is added, when it is missing, not a
  /// block file of this grid, or not as long as its block count says; and, the blocks before
  /// it added, naming the block that lies outside the tile, repeats an earlier one, or holds a
  /// voxel no writer makes (an sdf beyond the truncation, a weight below 0, either not
  /// finite, or flags other than the passes).
  void readTile(const GridIndex& tile, const std::function<void(const TsdfBlock&)>& add) const;
  /// Writes tile `tile`'s blocks (the integrator's flags zeroed), atomically.
  void writeTile(const GridIndex& tile, const std::vector<const TsdfBlock*>& blocks) const;
  /// Lists `tiles` (sorted here) in DIR/tsdf/index.txt, atomically; creates DIR/tsdf.
  void writeIndex(std::vector<GridIndex> tiles);

  /// The tile that holds block `block`.
  static GridIndex tileOf(const GridIndex& block, int tile_blocks);
  /// "X_Y_Z", the stem of a tile's files.
  static std::string tileName(const GridIndex& tile);
  /// Tiles in the order of the index: by x, then y, then z.
  static bool tileOrder(const GridIndex& a, const GridIndex& b);

private:
  /// Throws IOError unless the block file at `path` is exactly as long as `count` blocks.
  static void requireBlockBytes(const std::string& path, std::size_t count);

  std::string directory_;
  double voxel_size_, truncation_;
  int tile_blocks_;
  std::vector<GridIndex> tiles_;
};

} // namespace msf
