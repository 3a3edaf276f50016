// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/reconstruction/point_types.h>
#include <msf/reconstruction/tsdf_block.h>

#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace msf {

/// A sparse, boundless truncated signed distance volume (Curless and Levoy): blocks of 8^3
/// voxels allocated on demand in a hash map, as Voxblox's Layer and VDBFusion's VDBVolume
/// (stored ~340 to a 2 MiB chunk, so memoryBytes() grows in steps of 2 MiB).
/// Voxel v (integer grid coordinates) has its centre at v * voxelSize(), so the marching
/// cubes grid is the voxel centres.
///
/// The volume holds data only; TsdfIntegrator writes it and MarchingCubes reads it.
class TsdfVolume {
public:
  using Ptr = std::shared_ptr<TsdfVolume>;
  using ConstPtr = std::shared_ptr<const TsdfVolume>;

  /// Section `tsdf_volume` of a config file.
  struct Config {
    static constexpr const char* kSection = "tsdf_volume";
    static constexpr const char* kAbout = "TsdfVolume (paper step 5): the map, sparse hashed blocks of 8^3 voxels";
    double voxel_size_m = 0.1;
    double truncation_m = 0.3;
    /// The volume's blocks and map may not exceed the budget: a growth that would stops with an
    /// error before allocating. msf_reconstruct also refuses, before it starts, a run whose
    /// predicted peak (the whole process: Reconstructor::predictMemory) exceeds a budget given
    /// here or with -max_memory.
    double max_memory_mb = 0.0;

    template <class Keys>
    void keys(Keys& k) {
      k("voxel_size_m", voxel_size_m, between(kMinVoxelSizeM, kMaxVoxelSizeM), "edge of a voxel, m");
      k("truncation_m", truncation_m, above(0),
        "|sdf| is clamped here and observations update voxels within it, m (at most 64 voxels)");
      k("max_memory_mb", max_memory_mb, atLeast(0), "the map's memory budget, MiB (0: three quarters of the RAM)");
    }
    /// Throws ConfigError naming the key of a value out of range (see TsdfVolume::validate).
    void validate() const;
  };

  /// Voxels from 1 mm to 10 m; a truncation of at most kMaxTruncationVoxels voxels (and > 0).
  static constexpr double kMinVoxelSizeM = 1e-3;
  static constexpr double kMaxVoxelSizeM = 10.0;
  static constexpr double kMaxTruncationVoxels = 64.0;
  /// Throws ConfigError naming the key when voxel_size_m or truncation_m is outside the
  /// ranges above (or not finite), or max_memory_mb < 0.
  static void validate(double voxel_size_m, double truncation_m, double max_memory_mb = 0.0);

  /// Throws ConfigError as validate().
  TsdfVolume(double voxel_size_m, double truncation_m);
  explicit TsdfVolume(const Config& config) : TsdfVolume(config.voxel_size_m, config.truncation_m) {
    setMaxMemoryMb(config.max_memory_mb);
  }

  /// The memory budget of blocks and map (MiB, 0 = three quarters of RAM): an allocation
  /// that would exceed it throws InvalidInputError (naming the budget) before allocating.
  void setMaxMemoryMb(double max_memory_mb);
  std::size_t maxMemoryBytes() const { return max_memory_bytes_; }

  double voxelSize() const { return voxel_size_; }
  double truncation() const { return truncation_; }

  std::size_t numBlocks() const { return blocks_.size(); }
  /// Voxels with weight > 0 (a pass over every block).
  std::size_t numObservedVoxels() const;
  /// Bytes held by blocks and the hash map.
  std::size_t memoryBytes() const;
  /// Bytes a volume of `blocks` blocks holds when it grew to them (its chunks of blocks, map
  /// and block list, as the memory budget counts them): what a run that allocates them needs.
  static std::size_t bytesFor(std::size_t blocks);

  /// The block at `index`, or nullptr when it is not allocated.
  TsdfBlock* findBlock(const GridIndex& index);
  const TsdfBlock* findBlock(const GridIndex& index) const;
  /// The block at `index`, allocated (all voxels unobserved) when absent. Not thread-safe.
  TsdfBlock& allocateBlock(const GridIndex& index);
  /// allocateBlock for each index, the new blocks constructed in parallel: `blocks[i]` is
  /// the block at `indices[i]`. Not thread-safe (it runs its own threads).
  void allocateBlocks(const std::vector<GridIndex>& indices, std::vector<TsdfBlock*>& blocks);

  /// Where blocks not in memory may be (StreamingMap: tiles on disk). Called before blocks
  /// are allocated, with their indices: all that allocateBlocks is given, the one that
  /// allocateBlock is given when it is absent. It may put blocks in (allocateBlock), which
  /// the allocation then finds, so that an integrator never starts a block afresh where the
  /// map has one on disk. Its own allocations do not call it again. Empty: none.
  using BlockSource = std::function<void(const std::vector<GridIndex>& indices)>;
  void setBlockSource(BlockSource source) { source_ = std::move(source); }
  /// Every allocated block (stable addresses until removeBlocks).
  const std::vector<TsdfBlock*>& blocks() const { return blocks_; }
  /// Frees the blocks at `indices` (absent ones are ignored) and the memory they held: the
  /// last blocks move into the holes, so pointers to blocks are invalid afterwards and the
  /// order of blocks() changes. The cost is that of the removed blocks plus a rehash of the
  /// map, not a pass over the volume's voxels (StreamingMap calls it as the sensor moves on).
  void removeBlocks(const std::vector<GridIndex>& indices);

  /// The voxel with global index v, or nullptr when its block is not allocated.
  const TsdfVoxel* findVoxel(const GridIndex& v) const;
  /// Global index of the voxel whose centre is nearest to p (metres, world frame).
  GridIndex voxelIndexOf(const Eigen::Vector3d& p) const;
  /// Centre of global voxel v in metres.
  Eigen::Vector3d voxelCenter(const GridIndex& v) const { return v.cast<double>() * voxel_size_; }

  /// Change counter: each integration takes a new generation and stamps the blocks it
  /// changes with it, so MarchingCubes re-meshes only those.
  std::uint64_t generation() const { return generation_; }
  std::uint64_t beginGeneration() { return ++generation_; }
  /// Identity of the volume's content lineage; a new value after clear() or load(), which
  /// tells an incremental mesher to start over.
  std::uint64_t id() const { return id_; }

  /// Drops every block.
  void clear();

  /// Observed voxels (weight > min_weight) as points: centre, sdf, weight, colour.
  void toCloud(pcl::PointCloud<PointTsdf>& cloud, float min_weight = 0.f) const;
  /// Replaces the content with the voxels of `cloud` (centres on this volume's grid).
  /// Throws InvalidInputError naming the first point that is off the grid or not finite.
  void fromCloud(const pcl::PointCloud<PointTsdf>& cloud);

  /// Saves the observed voxels as a binary compressed .pcd of PointTsdf (x y z sdf weight
  /// rgb), with voxel size and truncation in a header comment
  /// ("# msfusion tsdf voxel_size_m 0.1 truncation_m 0.3"). Atomic. Throws IOError naming
  /// the file, InvalidInputError when the volume has no observed voxel.
  void save(const std::string& path) const;
  /// Loads a volume written by save(). A PCL rewrite of the file (pcl_convert_pcd_ascii_binary,
  /// pcl::io::savePCDFile) drops the header comment: then `voxel_size_m` and `truncation_m`
  /// (> 0) say what it held; 0 = from the comment. Throws IOError naming the file when it is
  /// missing, lacks a field, or has neither the comment nor the two values, ConfigError when
  /// a given value contradicts the comment.
  static TsdfVolume load(const std::string& path, double voxel_size_m = 0, double truncation_m = 0);

private:
  /// Replaces the content with the `count` voxels `at(i)` gives (PointTsdf: fromCloud's and
  /// load's), checked as fromCloud says.
  template <typename VoxelAt>
  void insertVoxels(std::size_t count, const VoxelAt& at);

  double voxel_size_;
  double truncation_;
  std::size_t max_memory_bytes_ = 0;
  std::uint64_t generation_ = 0;
  std::uint64_t id_;
  /// Open addressing (linear probing, load <= 1/2): lookups are in every inner loop that
  /// crosses a block border, and std::unordered_map's were a tenth of the meshing time.
  struct Slot {
    GridIndex key{0, 0, 0};
    std::int32_t block = -1; ///< position in blocks_, -1 = empty
  };
  std::size_t slotOf(const GridIndex& index) const;
  void grow();
  /// Room in the map and in the chunks for `blocks` blocks in all.
  void reserve(std::size_t blocks);
  /// Where block number `block` (position in blocks_) lives.
  void* storage(std::size_t block) const;
  /// Where each block's observed voxels (weight > min_weight) begin among all of them, block
  /// after block, and their number last: toCloud's order.
  std::vector<std::size_t> keptVoxelStarts(float min_weight) const;
  /// The field `name` of toCloud's points [point, point + count), from the blocks (`first`:
  /// keptVoxelStarts(0)), one value after another into `out`.
  void writeVoxelValues(const std::string& name, const std::vector<std::size_t>& first, std::size_t point,
                        std::size_t count, char* out) const;
  /// Calls source_ with `indices` unless there is none or it is running.
  void askSource(const std::vector<GridIndex>& indices);

  std::vector<Slot> table_;
  std::size_t mask_ = 0;
  /// Blocks live in chunks of 2 MiB (on huge pages where the system allows): a frame touches
  /// thousands of blocks across the map, and with one allocation per block each cost a page
  /// fault and a TLB miss of its own.
  struct ChunkFree {
    void operator()(void* chunk) const noexcept;
  };
  std::vector<std::unique_ptr<void, ChunkFree>> chunks_; ///< block b is in chunk b / (blocks per chunk)
  std::vector<TsdfBlock*> blocks_;
  BlockSource source_;
  bool in_source_ = false;
};

} // namespace msf
