// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/tsdf_store.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

namespace msf {

namespace fs = std::filesystem;

namespace {

constexpr int kSide = TsdfBlock::kSide;
constexpr char kBlockMagic[8] = {'M', 'S', 'F', 'B', 'L', 'K', '0', '1'};
constexpr const char* kIndexTag = "msfusion-tsdf-store 1";

std::string number(double v) {
  std::ostringstream ss;
  ss.precision(9);
  ss << v;
  return ss.str();
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)); }

std::string indexPath(const std::string& directory) { return (fs::path(directory) / "tsdf" / "index.txt").string(); }

constexpr std::size_t kHeaderBytes = sizeof(kBlockMagic) + 2 * sizeof(double) + 2 * sizeof(std::int32_t);
constexpr std::size_t kBlockBytes = 3 * sizeof(std::int32_t) + 4 + TsdfBlock::kVoxels * sizeof(TsdfVoxel);

/// What makes a voxel one no writer of ours makes (a file edited, damaged or of another
/// program), or "" when there is nothing: an sdf beyond the truncation or not finite, a
/// negative or non-finite weight, flags other than the passes and reappeared (the integrator's own bits are
/// zero on disk).
std::string voxelFault(const TsdfVoxel& v, double truncation) {
  const double sdf_limit = truncation * (1.0 + 1e-6); // the integrator clamps in float
  if (!std::isfinite(v.sdf) || std::abs(v.sdf) > sdf_limit)
    return "sdf " + number(v.sdf) + ", not within the truncation " + number(truncation) + " m";
  if (!std::isfinite(v.weight) || v.weight < 0.f)
    return "weight " + number(v.weight) + ", not a finite value >= 0";
  if (v.flags & ~TsdfVoxel::kSavedFlags)
    return "flags " + std::to_string(v.flags) + ", bits other than the passes' and reappeared's";
  return "";
}

/// What makes a block of tile `tile`'s file one no writer makes, or "" when there is nothing:
/// an index outside the tile, one an earlier block had (`seen`: a flag per block of the
/// tile), or a voxel's fault (voxelFault).
std::string blockFault(const TsdfBlock& block, const GridIndex& tile, int tile_blocks, double truncation,
                       std::vector<bool>& seen) {
  if (TsdfStore::tileOf(block.index, tile_blocks) != tile)
    return "has index " + TsdfStore::tileName(block.index) + ", outside tile " + TsdfStore::tileName(tile);
  const GridIndex local = block.index - tile * tile_blocks;
  const std::size_t slot = static_cast<std::size_t>((local.x() * tile_blocks + local.y()) * tile_blocks + local.z());
  if (seen[slot])
    return "has index " + TsdfStore::tileName(block.index) + ", as an earlier block has";
  seen[slot] = true;
  for (std::size_t v = 0; v < block.voxels.size(); ++v) {
    const std::string fault = voxelFault(block.voxels[v], truncation);
    if (!fault.empty())
      return "has voxel " + std::to_string(v) + " of " + fault;
  }
  return "";
}

} // namespace

TsdfStore::TsdfStore(std::string directory, double voxel_size_m, double truncation_m, int tile_blocks)
    : directory_(std::move(directory)), voxel_size_(voxel_size_m), truncation_(truncation_m), tile_blocks_(tile_blocks) {}

TsdfStore TsdfStore::open(const std::string& directory) {
  const std::string path = indexPath(directory);
  requireFile(path, "TSDF store index");
  std::ifstream in(path);
  std::string line;
  double voxel_size = 0, truncation = 0;
  int side = 0, tile_blocks = 0;
  std::size_t count = 0;
  std::string k1, k2, k3, k4, k5;
  if (!std::getline(in, line) || line != kIndexTag ||
      !(in >> k1 >> voxel_size >> k2 >> truncation >> k3 >> side >> k4 >> tile_blocks >> k5 >> count) ||
      k1 != "voxel_size_m" || k2 != "truncation_m" || k3 != "block_side" || k4 != "tile_blocks" || k5 != "tiles" ||
      side != kSide || !(voxel_size > 0) || !(truncation > 0))
    throw IOError("TSDF store index '" + path + "' is not one a StreamingMap wrote (first line '" + kIndexTag + "')");
  if (tile_blocks < 1 || tile_blocks > kMaxTileBlocks)
    throw IOError("TSDF store index '" + path + "' has tile_blocks " + std::to_string(tile_blocks) + ", outside 1.." +
                  std::to_string(kMaxTileBlocks));
  TsdfStore store(directory, voxel_size, truncation, tile_blocks);
  std::map<std::tuple<int, int, int>, std::size_t> listed; // a tile twice would be meshed twice
  for (std::size_t i = 0; i < count; ++i) {
    GridIndex t;
    if (!(in >> t.x() >> t.y() >> t.z()))
      throw IOError("TSDF store index '" + path + "' lists " + std::to_string(count) + " tiles but ends after " +
                    std::to_string(i));
    const auto [first, fresh] = listed.emplace(std::make_tuple(t.x(), t.y(), t.z()), i + 1);
    if (!fresh)
      throw IOError("TSDF store index '" + path + "' lists tile " + tileName(t) + " twice (tiles " +
                    std::to_string(first->second) + " and " + std::to_string(i + 1) + ")");
    store.tiles_.push_back(t);
  }
  return store;
}

bool TsdfStore::sameGrid(const TsdfStore& other) const {
  return close(voxel_size_, other.voxel_size_) && close(truncation_, other.truncation_) &&
         tile_blocks_ == other.tile_blocks_;
}

std::string TsdfStore::tileName(const GridIndex& t) {
  return std::to_string(t.x()) + "_" + std::to_string(t.y()) + "_" + std::to_string(t.z());
}

bool TsdfStore::tileOrder(const GridIndex& a, const GridIndex& b) {
  return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
}

GridIndex TsdfStore::tileOf(const GridIndex& b, int tile_blocks) {
  return {floorDiv(b.x(), tile_blocks), floorDiv(b.y(), tile_blocks), floorDiv(b.z(), tile_blocks)};
}

std::string TsdfStore::blockPath(const GridIndex& tile) const {
  return (fs::path(directory_) / "tsdf" / (tileName(tile) + ".blk")).string();
}

/// Block file: magic, voxel size and truncation (float64), block side and block count
/// (int32), then per block its index (3 x int32), its sign bits (2 bytes and 2 of padding)
/// and its 512 voxels as in memory (12 bytes each, the integrator's own flags zeroed; they are
/// zero between frames anyway), little-endian as the host.
void TsdfStore::writeTile(const GridIndex& tile, const std::vector<const TsdfBlock*>& blocks) const {
  const std::string path = blockPath(tile);
  writeStreamAtomically(path, [&](std::ostream& out) {
    out.write(kBlockMagic, sizeof(kBlockMagic));
    const std::int32_t header[2] = {kSide, static_cast<std::int32_t>(blocks.size())};
    out.write(reinterpret_cast<const char*>(&voxel_size_), sizeof(double));
    out.write(reinterpret_cast<const char*>(&truncation_), sizeof(double));
    out.write(reinterpret_cast<const char*>(header), sizeof(header));
    std::array<TsdfVoxel, TsdfBlock::kVoxels> voxels;
    for (const TsdfBlock* block : blocks) {
      const std::int32_t index[3] = {block->index.x(), block->index.y(), block->index.z()};
      out.write(reinterpret_cast<const char*>(index), sizeof(index));
      // The sign bits as the integrator left them (they may be set for voxels that changed
      // sign since: recomputing them would carve less than the map in memory does).
      const std::uint8_t bits[4] = {block->signs, block->negative_subblocks, 0, 0};
      out.write(reinterpret_cast<const char*>(bits), sizeof(bits));
      voxels = block->voxels;
      for (TsdfVoxel& v : voxels)
        v.flags &= TsdfVoxel::kSavedFlags;
      out.write(reinterpret_cast<const char*>(voxels.data()), sizeof(voxels));
    }
  });
}

void TsdfStore::readTile(const GridIndex& tile, const std::function<void(const TsdfBlock&)>& add) const {
  const std::string path = blockPath(tile);
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IOError("cannot read TSDF blocks '" + path + "'");
  char magic[8];
  double vs = 0, trunc = 0;
  std::int32_t header[2] = {0, 0};
  in.read(magic, sizeof(magic));
  in.read(reinterpret_cast<char*>(&vs), sizeof(double));
  in.read(reinterpret_cast<char*>(&trunc), sizeof(double));
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  if (!in || std::memcmp(magic, kBlockMagic, sizeof(magic)) != 0 || header[0] != kSide || header[1] < 0)
    throw IOError("TSDF blocks '" + path + "' are not a block file of msfusion");
  if (std::abs(vs - voxel_size_) > 1e-9 * voxel_size_ || std::abs(trunc - truncation_) > 1e-9 * truncation_)
    throw IOError("TSDF blocks '" + path + "' have voxel size " + number(vs) + " m and truncation " + number(trunc) +
                  " m, the store " + number(voxel_size_) + " and " + number(truncation_));
  const std::size_t count = static_cast<std::size_t>(header[1]);
  requireBlockBytes(path, count);
  const std::size_t per_side = static_cast<std::size_t>(tile_blocks_);
  std::vector<bool> seen(per_side * per_side * per_side, false); // a block twice would be meshed twice
  TsdfBlock block;
  for (std::size_t b = 0; b < count; ++b) {
    std::int32_t index[3] = {0, 0, 0};
    std::uint8_t bits[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(index), sizeof(index));
    in.read(reinterpret_cast<char*>(bits), sizeof(bits));
    in.read(reinterpret_cast<char*>(block.voxels.data()), sizeof(block.voxels));
    block.index = GridIndex(index[0], index[1], index[2]);
    const std::string fault = in ? blockFault(block, tile, tile_blocks_, truncation_, seen) : "cannot be read";
    if (!fault.empty())
      throw IOError("TSDF blocks '" + path + "': block " + std::to_string(b + 1) + " of " + std::to_string(count) +
                    " " + fault);
    block.signs = bits[0];
    block.negative_subblocks = bits[1];
    add(block);
  }
}

void TsdfStore::requireBlockBytes(const std::string& path, std::size_t count) {
  std::error_code e;
  const std::uintmax_t size = fs::file_size(path, e);
  const std::uintmax_t expected = kHeaderBytes + count * kBlockBytes;
  if (e || size != expected)
    throw IOError("TSDF blocks '" + path + "' declare " + std::to_string(count) + " blocks, " +
                  std::to_string(expected) + " bytes, but the file has " + (e ? "no size" : std::to_string(size)));
}

void TsdfStore::writeIndex(std::vector<GridIndex> tiles) {
  std::sort(tiles.begin(), tiles.end(), tileOrder);
  std::ostringstream ss;
  ss.precision(17);
  ss << kIndexTag << "\nvoxel_size_m " << voxel_size_ << "\ntruncation_m " << truncation_ << "\nblock_side " << kSide
     << "\ntile_blocks " << tile_blocks_ << "\ntiles " << tiles.size() << "\n";
  for (const GridIndex& t : tiles)
    ss << t.x() << " " << t.y() << " " << t.z() << "\n";
  const std::string text = ss.str();
  std::error_code e;
  fs::create_directories(fs::path(directory_) / "tsdf", e);
  writeStreamAtomically(indexPath(directory_), [&](std::ostream& out) { out << text; });
  tiles_ = std::move(tiles);
}

} // namespace msf
