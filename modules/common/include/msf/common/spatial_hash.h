// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

namespace msf {

/// The spatial hash of integer grid coordinates (Teschner et al. 2003, "Optimized Spatial
/// Hashing for Collision Detection of Deformable Objects"): each coordinate times a large odd
/// constant, the three xor'ed. The constants are the ones usually quoted; 19349663 is not prime
/// (41 x 471943), but a hash container iterates in its hash's order: with these constants the
/// containers that use them keep the order that what the project writes was made in.
constexpr std::uint64_t kSpatialHashX = 73856093u;
constexpr std::uint64_t kSpatialHashY = 19349663u;
constexpr std::uint64_t kSpatialHashZ = 83492791u;

/// The hash in 64-bit products: a signed coordinate is sign-extended, an unsigned 32-bit one
/// (the bits of a float) zero-extended.
inline std::size_t spatialHash(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::size_t>(static_cast<std::uint64_t>(x) * kSpatialHashX ^
                                  static_cast<std::uint64_t>(y) * kSpatialHashY ^
                                  static_cast<std::uint64_t>(z) * kSpatialHashZ);
}

/// The hash in 32-bit products, which wrap: the low 32 bits of spatialHash. TsdfVolume's block
/// map hashes with it.
inline std::uint32_t spatialHash32(std::int32_t x, std::int32_t y, std::int32_t z) {
  return static_cast<std::uint32_t>(x) * static_cast<std::uint32_t>(kSpatialHashX) ^
         static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(kSpatialHashY) ^
         static_cast<std::uint32_t>(z) * static_cast<std::uint32_t>(kSpatialHashZ);
}

/// spatialHash of a grid cell, for std::unordered_map<Eigen::Vector3i, T, CellHash>.
struct CellHash {
  std::size_t operator()(const Eigen::Vector3i& c) const noexcept { return spatialHash(c.x(), c.y(), c.z()); }
};

} // namespace msf
