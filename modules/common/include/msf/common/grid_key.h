// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>

#include <cstdint>

namespace msf {

/// Integer grid coordinates packed into one 64-bit key, `Bits` bits a coordinate, x in the
/// highest field and z in the lowest, each biased by 2^(Bits - 1). Coordinates in
/// [-2^(Bits - 1), 2^(Bits - 1)) give distinct keys, which unpack to them and sort as the
/// coordinates do (by x, then y, then z); others alias (modulo 2^Bits), so callers bound them.
/// TsdfIntegrator keys its sub-blocks with 20 bits (3 bits of a sub-block follow): +-2^19
/// blocks, +-419 km at 0.1 m voxels, which TsdfIntegrator::checkReach enforces; blocks and
/// tiles elsewhere take 21 (+-2^20), of which the blocks an integrator makes use half.
template <int Bits>
struct GridKey {
  static_assert(Bits > 0 && 3 * Bits <= 64, "three fields must fit in 64 bits");
  static constexpr std::int64_t kBias = std::int64_t(1) << (Bits - 1);
  static constexpr std::uint64_t kMask = (std::uint64_t(1) << Bits) - 1;

  static std::uint64_t pack(const Eigen::Vector3i& i) {
    return ((static_cast<std::uint64_t>(i.x() + kBias) & kMask) << (2 * Bits)) |
           ((static_cast<std::uint64_t>(i.y() + kBias) & kMask) << Bits) |
           (static_cast<std::uint64_t>(i.z() + kBias) & kMask);
  }
  static Eigen::Vector3i unpack(std::uint64_t key) {
    return {field(key >> (2 * Bits)), field(key >> Bits), field(key)};
  }

private:
  static int field(std::uint64_t bits) { return static_cast<int>(static_cast<std::int64_t>(bits & kMask) - kBias); }
};

} // namespace msf
