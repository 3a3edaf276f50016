// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace msf {

/// floor(x) as an int, for |x| < 2^31: std::floor without SSE4.1 (the build targets plain
/// x86-64) is a branchy sequence per coordinate, and every return of every scan takes three.
inline int floorToInt(double x) {
  const int i = static_cast<int>(x); // towards zero
  return i - (static_cast<double>(i) > x);
}

/// Integer coordinates of the voxel of edge 1 / inv_voxel_size that holds `p`.
inline Eigen::Vector3i voxelOf(const Eigen::Vector3d& p, double inv_voxel_size) {
  return {floorToInt(p.x() * inv_voxel_size), floorToInt(p.y() * inv_voxel_size), floorToInt(p.z() * inv_voxel_size)};
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
  /// Asks the processor to bring `key`'s slot into the cache, for a find or insert soon after:
  /// a table of a few thousand voxels is larger than the core's cache, and a look-up that
  /// waits for memory costs more than the rest of a point's work.
  void prefetch(std::uint64_t key) const {
    if (!slots_.empty())
      __builtin_prefetch(&slots_[slotOf(key)]);
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

/// Which voxels may be in a VoxelTable: one bit per hash of a key, 16 bits or more a voxel,
/// so that a few tens of kilobytes stay in the cache. A clear bit says the voxel is absent
/// without a look-up in the table (most of a search's 27 voxels are empty space, and a
/// look-up that finds nothing misses the cache as one that finds a voxel does); a set one, that
/// the table must tell (for the few absent voxels that share a bit with a present one).
class VoxelBits {
public:
  /// No voxel, room for `voxels` at 16 bits each.
  void reset(std::size_t voxels) {
    std::size_t bits = std::size_t(1) << 16;
    int log2 = 16;
    while (bits < 16 * voxels)
      bits *= 2, ++log2;
    words_.assign(bits / 64, 0);
    shift_ = 64 - log2;
    capacity_ = bits / 16;
  }
  /// Voxels it has room for before reset() should make it larger.
  std::size_t capacity() const { return capacity_; }
  void set(std::uint64_t key) {
    const std::size_t b = bit(key);
    words_[b >> 6] |= std::uint64_t(1) << (b & 63);
  }
  bool test(std::uint64_t key) const {
    const std::size_t b = bit(key);
    return (words_[b >> 6] >> (b & 63)) & 1;
  }

private:
  std::size_t bit(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0xC2B2AE3D27D4EB4Full) >> shift_); // another hash than the table's
  }
  std::vector<std::uint64_t> words_;
  int shift_ = 64;
  std::size_t capacity_ = 0;
};

} // namespace msf
