#pragma once
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace msf {

/// Integer coordinates of the voxel of edge 1 / inv_voxel_size that holds `p`.
inline Eigen::Vector3i voxelOf(const Eigen::Vector3d& p, double inv_voxel_size) {
  return {static_cast<int>(std::floor(p.x() * inv_voxel_size)), static_cast<int>(std::floor(p.y() * inv_voxel_size)),
          static_cast<int>(std::floor(p.z() * inv_voxel_size))};
}

/// A voxel's coordinates packed into 63 bits, 21 a coordinate: +-2^20 voxels, 1000 km at 1 m
/// voxels (a wider coordinate wraps around, so keep the voxels over 1 mm).
inline std::uint64_t voxelKey(const Eigen::Vector3i& v) {
  constexpr std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
  return (static_cast<std::uint64_t>(v.x()) & mask) | ((static_cast<std::uint64_t>(v.y()) & mask) << 21) |
         ((static_cast<std::uint64_t>(v.z()) & mask) << 42);
}

/// Voxel key -> index, open addressing with linear probing in one flat array. The local map
/// and the downsampling look up every point of every scan: a node-based std::unordered_map
/// allocates per voxel and misses the cache on each lookup, which costs more than the ICP.
/// No erase: the map rebuilds its table when it drops voxels.
class VoxelTable {
public:
  static constexpr int kAbsent = -1;

  void clear() {
    slots_.assign(slots_.size(), Slot{});
    size_ = 0;
  }
  /// Room for `n` keys at most half full, so probes stay short.
  void reserve(std::size_t n) {
    if (2 * n > slots_.size())
      rehash(2 * n);
  }
  std::size_t size() const { return size_; }

  int find(std::uint64_t key) const {
    if (slots_.empty())
      return kAbsent;
    for (std::size_t i = slotOf(key);; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.key == key)
        return s.value;
      if (s.key == kEmpty)
        return kAbsent;
    }
  }
  /// The value of `key`, inserting `value` when it is absent; `second` is true on insertion.
  std::pair<int, bool> insert(std::uint64_t key, int value) {
    reserve(size_ + 1);
    for (std::size_t i = slotOf(key);; i = (i + 1) & mask_) {
      Slot& s = slots_[i];
      if (s.key == key)
        return {s.value, false};
      if (s.key == kEmpty) {
        s = Slot{key, value};
        ++size_;
        return {value, true};
      }
    }
  }

private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0); // no packed key has bit 63 set
  struct Slot {
    std::uint64_t key = kEmpty;
    int value = kAbsent;
  };

  std::size_t slotOf(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_) & mask_; // Fibonacci hashing
  }
  void rehash(std::size_t at_least) {
    std::size_t capacity = 64;
    int bits = 6;
    while (capacity < at_least)
      capacity *= 2, ++bits;
    std::vector<Slot> old(capacity);
    old.swap(slots_);
    mask_ = capacity - 1;
    shift_ = 64 - bits;
    size_ = 0;
    for (const Slot& s : old)
      if (s.key != kEmpty)
        insert(s.key, s.value);
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

} // namespace msf
