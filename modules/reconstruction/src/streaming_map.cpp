// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/elapsed.h>
#include <msf/common/exceptions.h>
#include <msf/common/grid_key.h>
#include <msf/common/output_folder.h>
#include <msf/common/spatial_hash.h>
#include <msf/reconstruction/streaming_map.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace msf {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kSide = TsdfBlock::kSide;

std::string number(double v) {
  std::ostringstream ss;
  ss.precision(9);
  ss << v;
  return ss.str();
}

std::string meshPath(const std::string& tiles, const GridIndex& tile) {
  return (fs::path(tiles) / (TsdfStore::tileName(tile) + ".ply")).string();
}

/// Puts a block read from disk (or copied) into `volume`.
void putBlock(TsdfVolume& volume, const GridIndex& index, const TsdfBlock& source, std::uint64_t stamp) {
  TsdfBlock& block = volume.allocateBlock(index);
  block = source;
  block.index = index;
  block.stamp = stamp;
}

constexpr int kVertexBytes = 15, kFaceBytes = 13;

struct PlyCounts {
  std::size_t vertices = 0, faces = 0;
  std::streamoff data = 0; // where the binary data starts
};

PlyCounts readPlyHeader(std::ifstream& in, const std::string& path) {
  const char* expected[] = {"ply", "format binary_little_endian 1.0", nullptr, "property float x", "property float y",
                            "property float z", "property uchar red", "property uchar green", "property uchar blue",
                            nullptr, "property list uchar uint vertex_indices", "end_header"};
  PlyCounts counts;
  std::string line;
  int k = 0;
  while (k < 12 && std::getline(in, line)) {
    if (line.rfind("comment", 0) == 0)
      continue;
    bool ok = false;
    if (k == 2)
      ok = std::sscanf(line.c_str(), "element vertex %zu", &counts.vertices) == 1;
    else if (k == 9)
      ok = std::sscanf(line.c_str(), "element face %zu", &counts.faces) == 1;
    else
      ok = line == expected[k];
    if (!ok)
      throw IOError("mesh '" + path + "' is not a PLY that msfusion streams (line '" + line + "')");
    ++k;
  }
  if (k < 12)
    throw IOError("mesh '" + path + "' ends inside its PLY header");
  counts.data = in.tellg();
  return counts;
}

std::string plyHeader(std::size_t vertices, std::size_t faces) {
  return "ply\nformat binary_little_endian 1.0\ncomment msfusion streamed mesh\nelement vertex " +
         std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
         "property uchar blue\nelement face " +
         std::to_string(faces) + "\nproperty list uchar uint vertex_indices\nend_header\n";
}

/// Welds the tiles of a union: the vertices that two tiles can share, those on a tile's lower
/// border plane (x, y or z at a multiple of the tile's voxels, computed as the mesher does:
/// float(index) * voxel size), are looked up by position; every other vertex is its tile's
/// own. Only the border vertices are kept (a few % of the mesh).
class TileWelder {
public:
  TileWelder(double voxel_size, int tile_voxels) : vs_(static_cast<float>(voxel_size)), tile_voxels_(tile_voxels) {}

  /// Numbers the vertices of the next tile (`count` vertices of kVertexBytes at `data`), in
  /// the order of the tiles: new vertices get the next numbers, a border vertex seen in an
  /// earlier tile its number there. With `first` (what begin() returned for this tile
  /// the first time), numbers it again the same way. Fills `index` and `fresh` (whether the
  /// vertex is written with this tile).
  void number(const char* data, std::size_t count, std::uint32_t first, std::vector<std::uint32_t>& index,
              std::vector<char>& fresh) {
    index.resize(count);
    fresh.resize(count);
    std::uint32_t next = first;
    for (std::size_t i = 0; i < count; ++i) {
      const char* v = data + i * kVertexBytes;
      float p[3];
      std::memcpy(p, v, 12);
      if (!onBorder(p)) {
        index[i] = next++;
        fresh[i] = 1;
        continue;
      }
      Key key;
      std::memcpy(key.bits.data(), v, 12);
      const auto [it, inserted] = border_.emplace(key, next);
      index[i] = it->second;
      fresh[i] = it->second == next; // first seen here (inserted now, or in the first numbering)
      if (fresh[i])
        ++next;
    }
    next_ = std::max(next_, next);
  }
  std::uint32_t next() const { return next_; }

private:
  bool onBorder(const float* p) const {
    for (int k = 0; k < 3; ++k) {
      const float g = std::nearbyint(p[k] / vs_);
      if (static_cast<float>(g) * vs_ == p[k] && std::fabs(g) < 2e9f) {
        const auto i = static_cast<std::int64_t>(g);
        if (((i % tile_voxels_) + tile_voxels_) % tile_voxels_ == 0)
          return true;
      }
    }
    return false;
  }
  struct Key {
    std::array<std::uint32_t, 3> bits;
    bool operator==(const Key& o) const { return bits == o.bits; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return spatialHash(k.bits[0], k.bits[1], k.bits[2]);
    }
  };
  float vs_;
  std::int64_t tile_voxels_;
  std::unordered_map<Key, std::uint32_t, Hash> border_;
  std::uint32_t next_ = 0;
};

/// The union of the tile meshes `tiles` (existing files only) as one welded PLY at `path`
/// (tiles of `tile_voxels` voxels of `voxel_size`), read one tile at a time: vertices numbered
/// in a first pass, written in a second, triangles renumbered in a third. Returns the
/// triangles; writes nothing when there are none.
std::size_t writeUnion(const std::vector<std::string>& tiles, const std::string& path, double voxel_size,
                       int tile_voxels) {
  std::vector<std::string> present;
  std::vector<PlyCounts> counts;
  std::size_t faces = 0;
  for (const std::string& tile : tiles) {
    std::ifstream in(tile, std::ios::binary);
    if (!in)
      continue;
    counts.push_back(readPlyHeader(in, tile));
    present.push_back(tile);
    faces += counts.back().faces;
  }
  if (faces == 0)
    return 0;
  std::vector<char> buffer;
  const auto readVertices = [&](std::size_t i) {
    std::ifstream in(present[i], std::ios::binary);
    in.seekg(counts[i].data);
    buffer.resize(counts[i].vertices * kVertexBytes);
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (!in)
      throw IOError("mesh '" + present[i] + "' ends inside its vertices");
  };
  TileWelder welder(voxel_size, tile_voxels);
  std::vector<std::uint32_t> first(present.size()), index;
  std::vector<char> fresh;
  for (std::size_t i = 0; i < present.size(); ++i) {
    readVertices(i);
    first[i] = welder.next();
    if (first[i] + counts[i].vertices > std::numeric_limits<std::uint32_t>::max())
      throw IOError("mesh '" + path + "': more than 2^32 vertices");
    welder.number(buffer.data(), counts[i].vertices, first[i], index, fresh);
  }
  writeStreamAtomically(path, [&](std::ostream& out) {
    const std::string header = plyHeader(welder.next(), faces);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    for (std::size_t i = 0; i < present.size(); ++i) {
      readVertices(i);
      welder.number(buffer.data(), counts[i].vertices, first[i], index, fresh);
      std::size_t kept = 0;
      for (std::size_t v = 0; v < counts[i].vertices; ++v)
        if (fresh[v])
          std::memmove(buffer.data() + kept++ * kVertexBytes, buffer.data() + v * kVertexBytes, kVertexBytes);
      out.write(buffer.data(), static_cast<std::streamsize>(kept * kVertexBytes));
    }
    for (std::size_t i = 0; i < present.size(); ++i) {
      readVertices(i);
      welder.number(buffer.data(), counts[i].vertices, first[i], index, fresh);
      std::ifstream in(present[i], std::ios::binary);
      in.seekg(counts[i].data + static_cast<std::streamoff>(counts[i].vertices * kVertexBytes));
      buffer.resize(counts[i].faces * kFaceBytes);
      in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      if (!in)
        throw IOError("mesh '" + present[i] + "' ends inside its triangles");
      for (std::size_t f = 0; f < counts[i].faces; ++f) {
        char* p = buffer.data() + f * kFaceBytes + 1;
        for (int k = 0; k < 3; ++k) {
          std::uint32_t v;
          std::memcpy(&v, p + 4 * k, 4);
          if (v >= counts[i].vertices)
            throw IOError("mesh '" + present[i] + "': triangle " + std::to_string(f) + " is not 3 vertices of the mesh");
          std::memcpy(p + 4 * k, &index[v], 4);
        }
      }
      out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    }
  });
  return faces;
}

/// Blocks of tiles on disk, read on demand for the layer around the tiles being meshed.
class TileCache {
public:
  explicit TileCache(const TsdfStore& store) : store_(store) {}
  /// The voxels of block `index` of stored tile `tile`, or nullptr when the tile lacks it.
  const TsdfBlock* find(const GridIndex& tile, const GridIndex& index) {
    const std::string name = TsdfStore::tileName(tile);
    auto it = tiles_.find(name);
    if (it == tiles_.end()) {
      if (tiles_.size() >= 32)
        tiles_.clear(); // a tile's neighbours come in runs: a small cache holds them
      auto& blocks = tiles_[name];
      store_.readTile(tile, [&](const TsdfBlock& v) { blocks.emplace(key(v.index), std::make_unique<TsdfBlock>(v)); });
      it = tiles_.find(name);
    }
    auto b = it->second.find(key(index));
    return b == it->second.end() ? nullptr : b->second.get();
  }

private:
  static std::uint64_t key(const GridIndex& b) { return GridKey<21>::pack(b); }
  const TsdfStore& store_;
  std::unordered_map<std::string,
                     std::unordered_map<std::uint64_t, std::unique_ptr<TsdfBlock>>>
      tiles_;
};

/// Meshes tile `tile` whose blocks are `blocks` (indices) with the layer around it that its
/// cubes read (MarchingCubes::readNeighbours), each block taken from `memory` when there, else
/// from the store through `cache` when its tile `on_disk` says so. Writes TILES/X_Y_Z.ply (removes it when the tile has no
/// triangle). Returns the triangles.
template <typename OnDisk>
std::size_t meshTile(const GridIndex& tile, const std::vector<GridIndex>& blocks, const TsdfVolume* memory,
                     OnDisk&& on_disk, TileCache& cache, const MarchingCubes& mesher, int tile_blocks,
                     double voxel_size, double truncation, const std::string& tiles) {
  TsdfVolume part(voxel_size, truncation);
  const std::uint64_t stamp = part.beginGeneration();
  auto copy = [&](const GridIndex& b) {
    if (part.findBlock(b))
      return;
    if (memory)
      if (const TsdfBlock* block = memory->findBlock(b)) {
        putBlock(part, b, *block, stamp);
        return;
      }
    const GridIndex t = TsdfStore::tileOf(b, tile_blocks);
    if (on_disk(t))
      if (const auto* voxels = cache.find(t, b))
        putBlock(part, b, *voxels, stamp);
  };
  for (const GridIndex& b : blocks)
    copy(b);
  for (const GridIndex& b : blocks)
    for (const GridIndex& d : mesher.readNeighbours())
      if (TsdfStore::tileOf(b + d, tile_blocks) != tile)
        copy(b + d);
  TriangleMesh mesh;
  mesher.extractBlocks(part, blocks, mesh);
  const std::string path = meshPath(tiles, tile);
  if (mesh.triangles.empty()) {
    std::error_code e;
    fs::remove(path, e);
  } else {
    StreamingMap::writeMesh(path, mesh);
  }
  return mesh.triangles.size();
}

} // namespace

void StreamingMap::Config::validate() const { checkKeyRanges(*this); }

void StreamingMap::Config::requireRadius(double reach_m, double voxel_size_m) const {
  const double tile_m = tile_blocks * kSide * voxel_size_m;
  if (active_radius_m < reach_m + tile_m)
    throw ConfigError("streaming.active_radius_m " + number(active_radius_m) + " is below " +
                      number(reach_m + tile_m) + " m, the integrator's reach (" + number(reach_m) +
                      " m: how far from the camera it changes blocks, TsdfIntegrator::reach) plus a tile (" +
                      number(tile_m) + " m)");
}

StreamingMap::StreamingMap(TsdfVolume& volume, const Config& config, const MarchingCubes::Config& mesher,
                           double reach_m, const std::string& directory)
    : volume_(volume), config_(config), mesher_(mesher), reach_m_(reach_m), directory_(directory),
      store_(directory, volume.voxelSize(), volume.truncation(), config.tile_blocks) {
  config_.validate();
  if (!config_.enabled())
    throw ConfigError("StreamingMap: streaming.active_radius_m is 0 (off)");
  config_.requireRadius(reach_m_, volume_.voxelSize());
  ensureOutputDirectory(directory_);
  for (const char* sub : {"tsdf", "tiles"}) {
    const fs::path p = fs::path(directory_) / sub;
    std::error_code e;
    // An earlier run's tiles would join this one's union, and a folder of the user's is not ours to empty.
    if (fs::exists(p, e) && !fs::is_empty(p, e))
      throw IOError("folder '" + p.string() + "' is not empty: a streamed map starts in empty folders");
    fs::create_directories(p, e);
    if (e)
      throw IOError("cannot create folder '" + p.string() + "': " + e.message());
  }
  writeIndex();
  volume_.setBlockSource([this](const std::vector<GridIndex>& blocks) { readBackAround(blocks); });
}

StreamingMap::~StreamingMap() { volume_.setBlockSource(nullptr); }

std::string StreamingMap::tilesDirectory() const { return (fs::path(directory_) / "tiles").string(); }

double StreamingMap::minimumRadius() const { return reach_m_ + config_.tile_blocks * kSide * volume_.voxelSize(); }

StreamingMap::TileKey StreamingMap::tileOf(const GridIndex& block) const {
  const GridIndex t = TsdfStore::tileOf(block, config_.tile_blocks);
  return GridKey<21>::pack(t);
}

GridIndex StreamingMap::tileIndex(TileKey key) const { return GridKey<21>::unpack(key); }

double StreamingMap::distanceToTile(TileKey key, const Eigen::Vector3d& p, int grow_blocks) const {
  const int voxels = config_.tile_blocks * kSide;
  const Eigen::Vector3d lo = ((tileIndex(key) * voxels).array() - grow_blocks * kSide).cast<double>() * volume_.voxelSize();
  const Eigen::Vector3d hi = lo + Eigen::Vector3d::Constant((voxels - 1 + 2 * grow_blocks * kSide) * volume_.voxelSize());
  return (p.cwiseMax(lo).cwiseMin(hi) - p).norm();
}

void StreamingMap::beforeIntegration(const Eigen::Vector3d& sensor) {
  std::vector<TileKey> back;
  for (const TileKey t : evicted_)
    if (distanceToTile(t, sensor, 1) <= reach_m_)
      back.push_back(t);
  readBack(std::move(back));
}

void StreamingMap::readBackAround(const std::vector<GridIndex>& blocks) {
  if (evicted_.empty() || moving_blocks_)
    return; // the blocks this map puts in itself are not the integrator's
  // The tiles whose box grown by one block holds the block: its own and, for a block on its
  // tile's border, the tiles across it (those whose cubes or regularization read it).
  const int n = config_.tile_blocks;
  std::vector<TileKey> back;
  GridIndex last(std::numeric_limits<int>::min(), 0, 0);
  for (const GridIndex& b : blocks) {
    const GridIndex t = TsdfStore::tileOf(b, n);
    const GridIndex local = b - t * n;
    int lo[3], hi[3];
    bool inner = true;
    for (int a = 0; a < 3; ++a) {
      lo[a] = local[a] == 0 ? -1 : 0;
      hi[a] = local[a] == n - 1 ? 1 : 0;
      inner = inner && lo[a] == 0 && hi[a] == 0;
    }
    if (inner && t == last)
      continue; // blocks come in runs of a tile
    last = inner ? t : GridIndex(std::numeric_limits<int>::min(), 0, 0);
    for (int dz = lo[2]; dz <= hi[2]; ++dz)
      for (int dy = lo[1]; dy <= hi[1]; ++dy)
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          const TileKey k = tileOf((t + GridIndex(dx, dy, dz)) * n);
          if (evicted_.count(k))
            back.push_back(k);
        }
  }
  std::sort(back.begin(), back.end());
  back.erase(std::unique(back.begin(), back.end()), back.end());
  stats_.tiles_reloaded_on_allocation += back.size();
  readBack(std::move(back));
}

void StreamingMap::readBack(std::vector<TileKey> back) {
  if (back.empty())
    return;
  const auto t0 = Clock::now();
  std::sort(back.begin(), back.end());
  const std::uint64_t stamp = volume_.beginGeneration();
  const MovingBlocks moving(moving_blocks_);
  for (const TileKey t : back) {
    store_.readTile(tileIndex(t), [&](const TsdfBlock& voxels) {
      // A block of an evicted tile is never in memory: allocating one reads its tile first.
      if (volume_.findBlock(voxels.index))
        throw std::logic_error("StreamingMap: block " + TsdfStore::tileName(voxels.index) +
                               " of a tile on disk is in memory");
      putBlock(volume_, voxels.index, voxels, stamp);
      ++stats_.blocks_reloaded;
    });
    evicted_.erase(t);
    ++stats_.tiles_reloaded;
    // The tiles whose cubes read this tile's blocks (MarchingCubes::readNeighbours) may change their mesh.
    const GridIndex ti = tileIndex(t);
    for (const GridIndex& d : mesher_.readNeighbours()) {
      const GridIndex n = ti - d;
      const TileKey nk = tileOf(n * config_.tile_blocks);
      if (evicted_.count(nk))
        stale_.insert(nk);
    }
  }
  stats_.stream_ms += msSince(t0);
}

void StreamingMap::afterIntegration(const Eigen::Vector3d& sensor) {
  // A pass over the blocks' tiles is cheap but not free: once per quarter tile travelled.
  const double step = 0.25 * config_.tile_blocks * kSide * volume_.voxelSize();
  if ((sensor - last_check_).norm() < step)
    return;
  last_check_ = sensor;
  const auto t0 = Clock::now();
  std::unordered_set<TileKey> tiles;
  TileKey last = ~TileKey(0);
  for (const TsdfBlock* block : volume_.blocks()) {
    const TileKey t = tileOf(block->index);
    if (t != last)
      tiles.insert(t);
    last = t;
  }
  std::vector<TileKey> out;
  for (const TileKey t : tiles)
    if (distanceToTile(t, sensor, 1) > config_.active_radius_m)
      out.push_back(t);
  if (!out.empty())
    evict(out);
  stats_.stream_ms += msSince(t0);
}

void StreamingMap::evict(const std::vector<TileKey>& tiles_in) {
  std::vector<TileKey> tiles = tiles_in;
  std::sort(tiles.begin(), tiles.end());
  std::unordered_map<TileKey, std::vector<GridIndex>> blocks;
  for (const TileKey t : tiles)
    blocks[t];
  for (const TsdfBlock* block : volume_.blocks()) {
    auto it = blocks.find(tileOf(block->index));
    if (it != blocks.end())
      it->second.push_back(block->index);
  }
  const double vs = volume_.voxelSize(), trunc = volume_.truncation();
  TileCache cache(store_);
  const auto on_disk = [&](const GridIndex& t) { return evicted_.count(tileOf(t * config_.tile_blocks)) > 0; };
  std::vector<GridIndex> freed;
  for (const TileKey t : tiles) {
    std::vector<GridIndex>& mine = blocks[t];
    const GridIndex ti = tileIndex(t);
    if (evicted_.count(t)) // allocating a block of a tile on disk reads the tile back first
      throw std::logic_error("StreamingMap: tile " + TsdfStore::tileName(ti) + " is on disk and has blocks in memory");
    std::sort(mine.begin(), mine.end(), [](const GridIndex& a, const GridIndex& b) {
      return std::tie(a.z(), a.y(), a.x()) < std::tie(b.z(), b.y(), b.x());
    });
    meshTile(ti, mine, &volume_, on_disk, cache, mesher_, config_.tile_blocks, vs, trunc, tilesDirectory());
    std::vector<const TsdfBlock*> pointers;
    for (const GridIndex& b : mine)
      pointers.push_back(volume_.findBlock(b));
    store_.writeTile(ti, pointers);
    stored_.insert(t);
    evicted_.insert(t);
    stale_.erase(t);
    ++stats_.tiles_written;
    freed.insert(freed.end(), mine.begin(), mine.end());
  }
  volume_.removeBlocks(freed);
  stats_.blocks_freed += freed.size();
  writeIndex();
}

void StreamingMap::writeIndex() {
  std::vector<GridIndex> tiles;
  for (const TileKey k : stored_)
    tiles.push_back(tileIndex(k));
  store_.writeIndex(std::move(tiles));
}

std::size_t StreamingMap::finish(const std::string& mesh_path) {
  const auto t0 = Clock::now();
  std::unordered_set<TileKey> tiles;
  for (const TsdfBlock* block : volume_.blocks())
    tiles.insert(tileOf(block->index));
  if (!tiles.empty())
    evict(std::vector<TileKey>(tiles.begin(), tiles.end()));
  std::vector<TileKey> stale(stale_.begin(), stale_.end());
  std::sort(stale.begin(), stale.end());
  TileCache cache(store_);
  const auto on_disk = [&](const GridIndex& t) { return evicted_.count(tileOf(t * config_.tile_blocks)) > 0; };
  for (const TileKey t : stale) {
    std::vector<GridIndex> mine;
    store_.readTile(tileIndex(t), [&](const TsdfBlock& b) { mine.push_back(b.index); });
    meshTile(tileIndex(t), mine, nullptr, on_disk, cache, mesher_, config_.tile_blocks, volume_.voxelSize(),
             volume_.truncation(), tilesDirectory());
    ++stats_.tiles_remeshed;
  }
  stale_.clear();
  const std::size_t triangles = unionOfTiles(store_, store_.tiles(), tilesDirectory(), mesh_path);
  stats_.stream_ms += msSince(t0);
  return triangles;
}

TsdfVolume StreamingMap::loadStore(const std::string& directory) {
  const TsdfStore store = TsdfStore::open(directory);
  TsdfVolume volume(store.voxelSize(), store.truncation());
  const std::uint64_t stamp = volume.beginGeneration();
  for (const GridIndex& t : store.tiles())
    store.readTile(t, [&](const TsdfBlock& voxels) { putBlock(volume, voxels.index, voxels, stamp); });
  return volume;
}

std::size_t StreamingMap::meshTiles(const TsdfStore& store, const MarchingCubes::Config& mesher_config,
                                    const std::vector<GridIndex>& tiles, const std::string& tiles_directory) {
  const MarchingCubes mesher(mesher_config);
  TileCache cache(store);
  std::set<GridIndex, decltype(&TsdfStore::tileOrder)> stored(store.tiles().begin(), store.tiles().end(),
                                                              &TsdfStore::tileOrder);
  const auto on_disk = [&](const GridIndex& t) { return stored.count(t) > 0; };
  std::size_t triangles = 0;
  for (const GridIndex& t : tiles) {
    std::vector<GridIndex> mine;
    store.readTile(t, [&](const TsdfBlock& b) { mine.push_back(b.index); });
    triangles += meshTile(t, mine, nullptr, on_disk, cache, mesher, store.tileBlocks(), store.voxelSize(),
                          store.truncation(), tiles_directory);
  }
  return triangles;
}

std::size_t StreamingMap::unionOfTiles(const TsdfStore& store, const std::vector<GridIndex>& tiles,
                                       const std::string& tiles_directory, const std::string& mesh_path) {
  std::vector<GridIndex> sorted = tiles;
  std::sort(sorted.begin(), sorted.end(), TsdfStore::tileOrder);
  std::vector<std::string> meshes;
  for (const GridIndex& t : sorted)
    meshes.push_back(meshPath(tiles_directory, t));
  return writeUnion(meshes, mesh_path, store.voxelSize(), store.tileBlocks() * kSide);
}

std::size_t StreamingMap::remesh(const std::string& directory, const MarchingCubes::Config& mesher_config,
                                 const std::string& mesh_path, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const TsdfStore store = TsdfStore::open(directory);
  // The tiles' folder is an output folder of its own: replaced only when an earlier remesh wrote it.
  OutputFolder tiles_folder(mesh_path + ".tiles", "msf_mesh", {directory});
  const bool region = (lo.array() <= hi.array()).all();
  const double tile_m = store.tileSizeM();
  std::vector<GridIndex> chosen;
  for (const GridIndex& t : store.tiles()) {
    const Eigen::Vector3d tlo = t.cast<double>() * tile_m, thi = tlo + Eigen::Vector3d::Constant(tile_m);
    if (!region || ((thi.array() >= lo.array()).all() && (tlo.array() <= hi.array()).all()))
      chosen.push_back(t);
  }
  meshTiles(store, mesher_config, chosen, tiles_folder.dir());
  const std::size_t triangles = unionOfTiles(store, chosen, tiles_folder.dir(), mesh_path);
  tiles_folder.commit();
  return triangles;
}

void StreamingMap::writeMesh(const std::string& path, const TriangleMesh& mesh) {
  std::string data = plyHeader(mesh.vertices.size(), mesh.triangles.size());
  const std::size_t start = data.size();
  data.resize(start + mesh.vertices.size() * kVertexBytes + mesh.triangles.size() * kFaceBytes);
  char* p = data.data() + start;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i, p += kVertexBytes) {
    std::memcpy(p, mesh.vertices[i].data(), 12);
    std::memcpy(p + 12, mesh.colors[i].data(), 3);
  }
  for (const auto& t : mesh.triangles) {
    *p = 3;
    std::memcpy(p + 1, t.data(), 12);
    p += kFaceBytes;
  }
  writeBytesAtomically(path, data.data(), data.size());
}

void StreamingMap::transformMeshFile(const std::string& path, const Eigen::Isometry3d& T) {
  TriangleMesh mesh;
  readMesh(path, mesh);
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  for (auto& v : mesh.vertices)
    v = R * v + t;
  writeMesh(path, mesh);
}

void StreamingMap::readMesh(const std::string& path, TriangleMesh& mesh) {
  requireFile(path, "mesh");
  std::ifstream in(path, std::ios::binary);
  const PlyCounts counts = readPlyHeader(in, path);
  std::vector<char> buffer(counts.vertices * kVertexBytes + counts.faces * kFaceBytes);
  in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  if (!in)
    throw IOError("mesh '" + path + "' ends before its " + std::to_string(counts.faces) + " triangles");
  mesh.vertices.resize(counts.vertices);
  mesh.colors.resize(counts.vertices);
  mesh.triangles.resize(counts.faces);
  const char* p = buffer.data();
  for (std::size_t i = 0; i < counts.vertices; ++i, p += kVertexBytes) {
    std::memcpy(mesh.vertices[i].data(), p, 12);
    std::memcpy(mesh.colors[i].data(), p + 12, 3);
  }
  for (std::size_t f = 0; f < counts.faces; ++f, p += kFaceBytes) {
    std::memcpy(mesh.triangles[f].data(), p + 1, 12);
    if (*p != 3 || mesh.triangles[f][0] >= counts.vertices || mesh.triangles[f][1] >= counts.vertices ||
        mesh.triangles[f][2] >= counts.vertices)
      throw IOError("mesh '" + path + "': triangle " + std::to_string(f) + " is not 3 vertices of the mesh");
  }
}

void StreamingMap::weldByPosition(TriangleMesh& mesh) {
  struct Key {
    std::uint32_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return spatialHash(k.x, k.y, k.z);
    }
  };
  std::unordered_map<Key, std::uint32_t, Hash> seen;
  seen.reserve(mesh.vertices.size());
  std::vector<std::uint32_t> remap(mesh.vertices.size());
  TriangleMesh out;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    Key k;
    std::memcpy(&k.x, &mesh.vertices[i].x(), 4);
    std::memcpy(&k.y, &mesh.vertices[i].y(), 4);
    std::memcpy(&k.z, &mesh.vertices[i].z(), 4);
    const auto [it, inserted] = seen.emplace(k, static_cast<std::uint32_t>(out.vertices.size()));
    if (inserted) {
      out.vertices.push_back(mesh.vertices[i]);
      out.colors.push_back(mesh.colors[i]);
    }
    remap[i] = it->second;
  }
  out.triangles = mesh.triangles;
  for (auto& t : out.triangles)
    for (auto& v : t)
      v = remap[v];
  mesh = std::move(out);
}

} // namespace msf
