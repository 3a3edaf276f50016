// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/io/impl/cloud_io.hpp>
#include <msf/io/compressed_pcd.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <opencv2/core/utility.hpp>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>

#if __has_include(<sys/mman.h>)
#include <sys/mman.h> // madvise
#endif

#include <algorithm>
#include <atomic>
#include <cmath>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <numeric>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace msf {

namespace {
/// Whether a voxel is one of toCloud's points.
bool isKept(const TsdfVoxel& voxel, float min_weight) { return voxel.observed() && voxel.weight > min_weight; }

/// The centre of voxel `i` of `block` along `axis` (0 x, 1 y, 2 z), as toCloud's and save()'s
/// points have it.
float voxelCentre(const TsdfBlock& block, int i, int axis, float voxel_size) {
  constexpr int kBits = 3; // x fastest, then y, then z: kBits of the index each
  static_assert(TsdfBlock::kSide == 1 << kBits);
  return static_cast<float>(block.origin()[axis] + (i >> (kBits * axis) & (TsdfBlock::kSide - 1))) * voxel_size;
}

/// A voxel's colour as PCL packs it, opaque.
std::uint32_t voxelRgba(const TsdfVoxel& v) {
  return std::uint32_t{255} << 24 | std::uint32_t{v.r} << 16 | std::uint32_t{v.g} << 8 | std::uint32_t{v.b};
}

/// Voxel `i` of `block` as toCloud's and save()'s point: its centre, sdf, weight and colour.
PointTsdf voxelPoint(const TsdfBlock& block, int i, float voxel_size) {
  const TsdfVoxel& voxel = block.voxels[static_cast<std::size_t>(i)];
  PointTsdf p;
  p.x = voxelCentre(block, i, 0, voxel_size);
  p.y = voxelCentre(block, i, 1, voxel_size);
  p.z = voxelCentre(block, i, 2, voxel_size);
  p.sdf = voxel.sdf;
  p.weight = voxel.weight;
  p.rgba = voxelRgba(voxel);
  p.passes = static_cast<std::uint8_t>(voxel.passes());
  p.reappeared = voxel.reappeared() ? 1 : 0;
  return p;
}

std::uint64_t newVolumeId() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

std::string number(double v) {
  std::ostringstream ss;
  ss.precision(9);
  ss << v;
  return ss.str();
}

/// A float as a file would have given it: 0.05, not the 0.0500000007 of its nearest double.
std::string floatText(float v) {
  std::ostringstream ss;
  ss.precision(std::numeric_limits<float>::digits10 + 1);
  ss << v;
  return ss.str();
}

constexpr const char* kHeaderTag = "# msfusion tsdf";

/// The voxels of a volume file where its reader left them: each field read at its offset, no
/// cloud of them made (the largest allocation of a load). passes and reappeared, which files
/// written before them lack, are 0 there.
class BlobVoxels {
public:
  /// Throws IOError naming `path` and the field when the blob lacks one a voxel needs, or one
  /// holds values its type cannot (convertFieldTypes).
  BlobVoxels(pcl::PCLPointCloud2& blob, const std::string& path) : blob_(blob) {
    std::vector<pcl::PCLPointField> wanted;
    pcl::for_each_type<pcl::traits::fieldList<PointTsdf>::type>(pcl::detail::FieldAdder<PointTsdf>(wanted));
    wanted.erase(std::remove_if(wanted.begin(), wanted.end(),
                                [&](const pcl::PCLPointField& f) {
                                  return (f.name == "passes" || f.name == "reappeared") &&
                                         pcl::getFieldIndex(blob, f.name) < 0;
                                }),
                 wanted.end());
    requireFields(blob, wanted, path);
    convertFieldTypes(blob, wanted, path);
    const auto offset = [&](const char* name) {
      const int i = pcl::getFieldIndex(blob, name);
      return i < 0 ? -1 : static_cast<long>(blob.fields[static_cast<std::size_t>(i)].offset);
    };
    for (const char* name : {"x", "y", "z", "sdf", "weight"})
      float_offsets_.push_back(static_cast<std::size_t>(offset(name)));
    rgb_ = static_cast<std::size_t>(std::max(offset("rgb"), offset("rgba")));
    passes_ = offset("passes");
    reappeared_ = offset("reappeared");
    dense_ = blob.row_step == static_cast<std::uint64_t>(blob.width) * blob.point_step;
  }

  std::size_t size() const { return static_cast<std::size_t>(blob_.width) * blob_.height; }

  PointTsdf operator()(std::size_t i) const {
    const std::uint8_t* p = blob_.data.data() + (dense_ ? i * blob_.point_step
                                                        : i / blob_.width * blob_.row_step +
                                                              i % blob_.width * blob_.point_step);
    PointTsdf v;
    float* floats[] = {&v.x, &v.y, &v.z, &v.sdf, &v.weight};
    for (std::size_t f = 0; f < 5; ++f)
      std::memcpy(floats[f], p + float_offsets_[f], sizeof(float));
    std::memcpy(&v.rgba, p + rgb_, sizeof(v.rgba));
    v.passes = passes_ < 0 ? 0 : p[passes_];
    v.reappeared = reappeared_ < 0 ? 0 : p[reappeared_];
    return v;
  }

private:
  const pcl::PCLPointCloud2& blob_;
  std::vector<std::size_t> float_offsets_; // x y z sdf weight
  std::size_t rgb_ = 0;
  long passes_ = -1, reappeared_ = -1;     // -1: not in the file
  bool dense_ = true;                      // no padding at the rows' ends
};

// TsdfBlock is trivially destructible: a chunk is freed without destroying its blocks.
static_assert(std::is_trivially_destructible_v<TsdfBlock>);
constexpr std::size_t kChunkBytes = std::size_t(2) << 20; // a huge page on x86-64
constexpr std::size_t kBlocksPerChunk = kChunkBytes / sizeof(TsdfBlock);
} // namespace

void TsdfVolume::Config::validate() const {
  TsdfVolume::validate(voxel_size_m, truncation_m, max_memory_mb); // names the tools' options too
  checkKeyRanges(*this);
}

void TsdfVolume::validate(double voxel_size_m, double truncation_m, double max_memory_mb) {
  if (!(voxel_size_m >= kMinVoxelSizeM && voxel_size_m <= kMaxVoxelSizeM))
    throw ConfigError("tsdf_volume.voxel_size_m (-voxel, the voxel size) must be " + number(kMinVoxelSizeM) + " .. " +
                      number(kMaxVoxelSizeM) + " m, got " + number(voxel_size_m));
  if (!(truncation_m > 0.0 && truncation_m <= kMaxTruncationVoxels * voxel_size_m))
    throw ConfigError("tsdf_volume.truncation_m (-trunc) must be > 0 and at most " + number(kMaxTruncationVoxels) +
                      " voxels (" + number(kMaxTruncationVoxels * voxel_size_m) + " m), got " + number(truncation_m));
  if (!(max_memory_mb >= 0.0) || !std::isfinite(max_memory_mb))
    throw ConfigError("tsdf_volume.max_memory_mb (-max_memory) must be >= 0 (0: three quarters of RAM), got " +
                      number(max_memory_mb));
}

void TsdfVolume::setMaxMemoryMb(double max_memory_mb) {
  validate(voxel_size_, truncation_, max_memory_mb);
  if (max_memory_mb > 0.0) {
    max_memory_bytes_ = static_cast<std::size_t>(std::min(max_memory_mb, 1e12) * 1024.0 * 1024.0);
  } else {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    max_memory_bytes_ = pages > 0 && page > 0 ? static_cast<std::size_t>(pages) / 4 * 3 * static_cast<std::size_t>(page)
                                              : std::size_t(8) << 30;
  }
}

TsdfVolume::TsdfVolume(double voxel_size_m, double truncation_m)
    : voxel_size_(voxel_size_m), truncation_(truncation_m), id_(newVolumeId()) {
  setMaxMemoryMb(0.0);
}

std::size_t TsdfVolume::numObservedVoxels() const {
  std::size_t n = 0;
  for (const auto& block : blocks_)
    for (const auto& voxel : block->voxels)
      n += voxel.observed() ? 1 : 0;
  return n;
}

std::size_t TsdfVolume::memoryBytes() const {
  // Blocks, the pointer vector, and the map's buckets and nodes (key, value, next, hash).
  return chunks_.size() * kChunkBytes + blocks_.capacity() * sizeof(void*) + table_.capacity() * sizeof(Slot);
}

std::size_t TsdfVolume::bytesFor(std::size_t blocks) {
  // As reserve() grows: the map's slots a power of two from 1024 with load <= 1/2, whole chunks.
  std::size_t table = 1024;
  while (2 * blocks > table)
    table *= 2;
  const std::size_t chunks = (blocks + kBlocksPerChunk - 1) / kBlocksPerChunk;
  return chunks * kChunkBytes + table * sizeof(Slot) + blocks * sizeof(void*);
}

std::size_t TsdfVolume::slotOf(const GridIndex& index) const {
  std::uint64_t h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(index.x())) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(static_cast<std::uint32_t>(index.y())) * 0xC2B2AE3D27D4EB4Full ^
                    static_cast<std::uint64_t>(static_cast<std::uint32_t>(index.z())) * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  std::size_t i = static_cast<std::size_t>(h) & mask_;
  while (table_[i].block >= 0 && table_[i].key != index)
    i = (i + 1) & mask_;
  return i;
}

void TsdfVolume::grow() {
  // Rehashed from the slots themselves: blocks being allocated may not be constructed yet.
  std::vector<Slot> old = std::move(table_);
  const std::size_t capacity = old.empty() ? 1024 : 2 * old.size();
  table_.assign(capacity, Slot());
  mask_ = capacity - 1;
  for (const Slot& slot : old)
    if (slot.block >= 0)
      table_[slotOf(slot.key)] = slot;
}

void TsdfVolume::reserve(std::size_t blocks) {
  // The budget is checked on what this call would hold, before any allocation.
  std::size_t table = table_.size();
  while (2 * blocks > table)
    table = table ? 2 * table : 1024;
  const std::size_t chunks = (blocks + kBlocksPerChunk - 1) / kBlocksPerChunk;
  const std::size_t bytes = std::max(chunks, chunks_.size()) * kChunkBytes + table * sizeof(Slot) +
                            std::max(blocks, blocks_.capacity()) * sizeof(void*);
  if (bytes > max_memory_bytes_)
    throw InvalidInputError("the TSDF volume needs " + std::to_string(bytes >> 20) + " MiB for " +
                            std::to_string(blocks) + " blocks of " + number(voxel_size_) +
                            " m voxels, over its memory budget of " + std::to_string(max_memory_bytes_ >> 20) +
                            " MiB (tsdf_volume.max_memory_mb, -max_memory): use larger voxels, fewer frames or a "
                            "larger budget");
  while (2 * blocks > table_.size())
    grow();
  while (chunks_.size() * kBlocksPerChunk < blocks) {
    void* chunk = std::aligned_alloc(kChunkBytes, kChunkBytes);
    if (!chunk)
      throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    madvise(chunk, kChunkBytes, MADV_HUGEPAGE); // a hint: without it the chunk has 4 KiB pages
#endif
    chunks_.emplace_back(chunk);
  }
  blocks_.reserve(blocks);
}

void* TsdfVolume::storage(std::size_t block) const {
  return static_cast<char*>(chunks_[block / kBlocksPerChunk].get()) + (block % kBlocksPerChunk) * sizeof(TsdfBlock);
}

TsdfBlock* TsdfVolume::findBlock(const GridIndex& index) {
  if (table_.empty())
    return nullptr;
  const Slot& slot = table_[slotOf(index)];
  return slot.block >= 0 ? blocks_[static_cast<std::size_t>(slot.block)] : nullptr;
}

const TsdfBlock* TsdfVolume::findBlock(const GridIndex& index) const {
  return const_cast<TsdfVolume*>(this)->findBlock(index);
}

void TsdfVolume::askSource(const std::vector<GridIndex>& indices) {
  if (!source_ || in_source_ || indices.empty())
    return;
  in_source_ = true;
  try {
    source_(indices);
  } catch (...) {
    in_source_ = false;
    throw;
  }
  in_source_ = false;
}

TsdfBlock& TsdfVolume::allocateBlock(const GridIndex& index) {
  if (source_ && !in_source_ && !findBlock(index))
    askSource({index});
  reserve(blocks_.size() + 1); // may throw: before anything changes
  Slot& slot = table_[slotOf(index)];
  if (slot.block < 0) {
    slot.key = index;
    slot.block = static_cast<std::int32_t>(blocks_.size());
    auto* block = new (storage(blocks_.size())) TsdfBlock();
    block->index = index;
    blocks_.push_back(block);
  }
  return *blocks_[static_cast<std::size_t>(slot.block)];
}

void TsdfVolume::allocateBlocks(const std::vector<GridIndex>& indices, std::vector<TsdfBlock*>& blocks) {
  askSource(indices);
  std::size_t missing = 0;
  for (const GridIndex& index : indices)
    missing += findBlock(index) == nullptr;
  reserve(blocks_.size() + missing); // may throw: before anything changes
  // Serially into the map; the new blocks are constructed (6 KiB of zeros each, and the
  // first touch of their pages) afterwards, in parallel.
  std::vector<std::int32_t> position(indices.size());
  std::vector<std::size_t> fresh; // positions in indices
  const std::size_t before = blocks_.size();
  for (std::size_t i = 0; i < indices.size(); ++i) {
    Slot& slot = table_[slotOf(indices[i])];
    if (slot.block < 0) {
      slot.key = indices[i];
      slot.block = static_cast<std::int32_t>(blocks_.size());
      blocks_.push_back(nullptr);
      fresh.push_back(i);
    }
    position[i] = slot.block;
  }
  parallelFor(cv::Range(0, static_cast<int>(fresh.size())), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const std::size_t b = before + static_cast<std::size_t>(k);
      auto* block = new (storage(b)) TsdfBlock();
      block->index = indices[fresh[static_cast<std::size_t>(k)]];
      blocks_[b] = block;
    }
  }, std::max(1.0, static_cast<double>(fresh.size()) / 64));
  blocks.resize(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
    blocks[i] = blocks_[static_cast<std::size_t>(position[i])];
}

void TsdfVolume::removeBlocks(const std::vector<GridIndex>& indices) {
  if (indices.empty() || blocks_.empty())
    return;
  std::vector<char> gone(blocks_.size(), 0);
  std::size_t removed = 0;
  for (const GridIndex& index : indices) {
    const Slot& slot = table_[slotOf(index)];
    if (slot.block >= 0 && !gone[static_cast<std::size_t>(slot.block)]) {
      gone[static_cast<std::size_t>(slot.block)] = 1;
      ++removed;
    }
  }
  // Each hole below the new count takes a surviving block from the end.
  const std::size_t keep = blocks_.size() - removed;
  std::size_t from = blocks_.size();
  for (std::size_t hole = 0; hole < keep; ++hole) {
    if (!gone[hole])
      continue;
    do
      --from;
    while (gone[from]);
    blocks_[hole] = new (storage(hole)) TsdfBlock(*blocks_[from]);
  }
  blocks_.resize(keep);
  chunks_.resize((keep + kBlocksPerChunk - 1) / kBlocksPerChunk);
  std::size_t capacity = 1024;
  while (capacity < 2 * keep)
    capacity <<= 1;
  std::vector<Slot>(capacity).swap(table_);
  mask_ = capacity - 1;
  for (std::size_t b = 0; b < keep; ++b) {
    Slot& slot = table_[slotOf(blocks_[b]->index)];
    slot.key = blocks_[b]->index;
    slot.block = static_cast<std::int32_t>(b);
  }
}

void TsdfVolume::ChunkFree::operator()(void* chunk) const noexcept { std::free(chunk); }

const TsdfVoxel* TsdfVolume::findVoxel(const GridIndex& v) const {
  const GridIndex b = blockOf(v);
  const TsdfBlock* block = findBlock(b);
  if (!block)
    return nullptr;
  const GridIndex l = v - b * TsdfBlock::kSide;
  return &block->at(l.x(), l.y(), l.z());
}

GridIndex TsdfVolume::voxelIndexOf(const Eigen::Vector3d& p) const {
  return {static_cast<int>(std::lround(p.x() / voxel_size_)), static_cast<int>(std::lround(p.y() / voxel_size_)),
          static_cast<int>(std::lround(p.z() / voxel_size_))};
}

void TsdfVolume::clear() {
  table_.clear();
  mask_ = 0;
  blocks_.clear();
  chunks_.clear();
  id_ = newVolumeId();
}

std::vector<std::size_t> TsdfVolume::keptVoxelStarts(float min_weight) const {
  std::vector<std::size_t> first(blocks_.size() + 1, 0);
  parallelFor(cv::Range(0, static_cast<int>(blocks_.size())), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b)
      first[static_cast<std::size_t>(b) + 1] = static_cast<std::size_t>(std::count_if(
          std::begin(blocks_[b]->voxels), std::end(blocks_[b]->voxels),
          [min_weight](const TsdfVoxel& voxel) { return isKept(voxel, min_weight); }));
  });
  std::partial_sum(first.begin(), first.end(), first.begin());
  return first;
}

void TsdfVolume::toCloud(pcl::PointCloud<PointTsdf>& cloud, float min_weight) const {
  const auto kept = [min_weight](const TsdfVoxel& voxel) { return isKept(voxel, min_weight); };
  // Each block's place in the cloud first, so that the blocks fill theirs side by side, in order.
  const int blocks = static_cast<int>(blocks_.size());
  const std::vector<std::size_t> first = keptVoxelStarts(min_weight);
  cloud.clear();
  cloud.resize(first.back());
  const float vs = static_cast<float>(voxel_size_);
  parallelFor(cv::Range(0, blocks), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const TsdfBlock& block = *blocks_[b];
      PointTsdf* p = &cloud[first[static_cast<std::size_t>(b)]];
      for (int i = 0; i < TsdfBlock::kVoxels; ++i) // x fastest, then y, then z
        if (kept(block.voxels[static_cast<std::size_t>(i)]))
          *p++ = voxelPoint(block, i, vs);
    }
  });
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
}

void TsdfVolume::fromCloud(const pcl::PointCloud<PointTsdf>& cloud) {
  insertVoxels(cloud.size(), [&cloud](std::size_t i) -> const PointTsdf& { return cloud[i]; });
}

template <typename VoxelAt>
void TsdfVolume::insertVoxels(std::size_t count, const VoxelAt& at) {
  clear();
  const double tolerance = 0.01; // of a voxel: float coordinates of far voxels round a little
  TsdfBlock* current = nullptr;  // the last voxel's: a file holds its voxels block by block
  GridIndex current_index = GridIndex::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    const PointTsdf& p = at(i);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.sdf) ||
        !std::isfinite(p.weight))
      throw InvalidInputError("voxel " + std::to_string(i) + " has a coordinate, sdf or weight that is not a finite value");
    if (p.weight < 0.f)
      throw InvalidInputError("voxel " + std::to_string(i) + " has a negative weight (" + floatText(p.weight) + ")");
    if (p.passes > TsdfVoxel::kMaxPasses) // no writer makes it: a file edited or of another program
      throw InvalidInputError("voxel " + std::to_string(i) + " has passes " + std::to_string(p.passes) +
                              ", more than the " + std::to_string(TsdfVoxel::kMaxPasses) + " a voxel counts");
    if (p.reappeared > 1)
      throw InvalidInputError("voxel " + std::to_string(i) + " has reappeared " + std::to_string(p.reappeared) +
                              ", not 0 or 1");
    const Eigen::Vector3d q(p.x, p.y, p.z);
    const GridIndex v = voxelIndexOf(q);
    if (((q / voxel_size_) - v.cast<double>()).cwiseAbs().maxCoeff() > tolerance)
      throw InvalidInputError("voxel " + std::to_string(i) + " at (" + floatText(p.x) + ", " + floatText(p.y) + ", " +
                              floatText(p.z) + ") is not on the " + number(voxel_size_) + " m grid");
    const GridIndex b = blockOf(v);
    if (!current || b != current_index) {
      current = &allocateBlock(b);
      current_index = b;
    }
    const GridIndex l = v - b * TsdfBlock::kSide;
    TsdfVoxel& voxel = current->at(l.x(), l.y(), l.z());
    voxel.sdf = std::max(-static_cast<float>(truncation_), std::min(static_cast<float>(truncation_), p.sdf));
    voxel.weight = p.weight;
    voxel.r = p.r;
    voxel.g = p.g;
    voxel.b = p.b;
    voxel.flags =
        static_cast<std::uint8_t>(p.passes << TsdfVoxel::kPassesShift | (p.reappeared ? TsdfVoxel::kReappeared : 0));
  }
  const std::uint64_t stamp = beginGeneration();
  for (auto& block : blocks_) {
    block->stamp = stamp;
    block->updateSigns();
  }
}

void TsdfVolume::writeVoxelValues(const std::string& name, const std::vector<std::size_t>& first, std::size_t point,
                                  std::size_t count, char* out) const {
  // Each field from the voxel alone, as voxelPoint has it: a whole point per value would be
  // built once per field.
  const auto each = [&](const auto& value) {
    auto b = static_cast<std::size_t>(std::upper_bound(first.begin(), first.end(), point) - first.begin()) - 1;
    std::size_t skip = point - first[b];
    for (; count > 0; ++b) {
      const TsdfBlock& block = *blocks_[b];
      for (int i = 0; i < TsdfBlock::kVoxels && count > 0; ++i) {
        if (!isKept(block.voxels[static_cast<std::size_t>(i)], 0.f))
          continue;
        if (skip > 0) {
          --skip;
          continue;
        }
        const auto v = value(block, i);
        std::memcpy(out, &v, sizeof v);
        out += sizeof v;
        --count;
      }
    }
  };
  const float vs = static_cast<float>(voxel_size_);
  const auto voxel = [](const TsdfBlock& block, int i) -> const TsdfVoxel& {
    return block.voxels[static_cast<std::size_t>(i)];
  };
  if (name == "x" || name == "y" || name == "z") {
    const int axis = name[0] - 'x';
    each([&](const TsdfBlock& block, int i) { return voxelCentre(block, i, axis, vs); });
  } else if (name == "sdf") {
    each([&](const TsdfBlock& block, int i) { return voxel(block, i).sdf; });
  } else if (name == "weight") {
    each([&](const TsdfBlock& block, int i) { return voxel(block, i).weight; });
  } else if (name == "rgb") {
    each([&](const TsdfBlock& block, int i) { return voxelRgba(voxel(block, i)); });
  } else if (name == "passes") {
    each([&](const TsdfBlock& block, int i) { return static_cast<std::uint8_t>(voxel(block, i).passes()); });
  } else if (name == "reappeared") {
    each([&](const TsdfBlock& block, int i) { return std::uint8_t{voxel(block, i).reappeared()}; });
  } else {
    throw std::logic_error("TsdfVolume::writeVoxelValues: no field '" + name + "' in a PointTsdf");
  }
}

void TsdfVolume::save(const std::string& path) const {
  if (fileExtension(path) != ".pcd")
    throw IOError("cannot write volume '" + path + "': a TSDF volume is written as .pcd");
  const std::vector<std::size_t> first = keptVoxelStarts(0.f);
  if (first.back() == 0)
    throw InvalidInputError("cannot write volume '" + path + "': it has no observed voxel");
  // The voxels' values straight from the blocks, the bytes toCloud's cloud would give: no
  // cloud of them is made, which would be the largest allocation at the end of a run.
  const pcl::PCLPointCloud2 layout = pointLayout<PointTsdf>(static_cast<std::uint32_t>(first.back()), 1, true);
  std::vector<const pcl::PCLPointField*> fields; // where each lies in a PointTsdf
  for (const pcl::PCLPointField& f : layout.fields)
    if (f.name != "_")
      fields.push_back(&f);
  const FieldValues values = [&](std::size_t field, std::size_t point, std::size_t count, char* out) {
    writeVoxelValues(fields[field]->name, first, point, count, out);
  };
  // The parameters go into a comment line after the file's first line, which PCD readers
  // (pcl_viewer included) skip.
  const std::string comment = std::string(kHeaderTag) + " voxel_size_m " + number(voxel_size_) + " truncation_m " +
                              number(truncation_) + "\n";
  writeStreamAtomically(path, [&](std::ostream& out) {
    writeCompressedPcd(out, layout, values, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), comment);
  });
}

TsdfVolume TsdfVolume::load(const std::string& path, double voxel_size_m, double truncation_m) {
  requireFile(path, "volume");
  double voxel_size = 0.0, truncation = 0.0;
  {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    bool found = false;
    for (int n = 0; n < 32 && std::getline(in, line); ++n) {
      if (line.rfind("DATA", 0) == 0)
        break;
      if (line.rfind(kHeaderTag, 0) == 0) {
        std::istringstream ss(line.substr(std::string(kHeaderTag).size()));
        std::string k1, k2;
        found = static_cast<bool>(ss >> k1 >> voxel_size >> k2 >> truncation) && k1 == "voxel_size_m" &&
                k2 == "truncation_m";
        break;
      }
    }
    auto given = [&](double value, double& from_file, const char* name) {
      if (value <= 0.0)
        return;
      if (found && std::abs(value - from_file) > 1e-9 * std::max(1.0, from_file))
        throw ConfigError("volume '" + path + "' was written with " + name + " " + number(from_file) + ", not " +
                          number(value));
      from_file = value;
    };
    given(voxel_size_m, voxel_size, "voxel_size_m");
    given(truncation_m, truncation, "truncation_m");
    if (!found && !(voxel_size > 0.0 && truncation > 0.0))
      throw IOError("volume '" + path + "' has no header comment '" + kHeaderTag +
                    " voxel_size_m V truncation_m T' (a PCL rewrite drops it): give the voxel size and "
                    "truncation it was made with (msf_mesh -voxel V -trunc T)");
  }
  TsdfVolume volume(voxel_size, truncation);
  pcl::PCLPointCloud2 blob;
  loadCloudBlob(path, blob);
  const BlobVoxels voxels(blob, path);
  try {
    volume.insertVoxels(voxels.size(), voxels);
  } catch (const InvalidInputError& e) {
    throw IOError("volume '" + path + "': " + e.what());
  }
  return volume;
}

} // namespace msf
