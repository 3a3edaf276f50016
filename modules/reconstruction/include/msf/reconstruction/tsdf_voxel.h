// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstdint>

namespace msf {

/// One voxel of a TSDF volume (as Voxblox's TsdfVoxel): signed distance to the nearest
/// surface along the viewing direction in metres (positive in front of the surface, in free
/// space; negative behind it), clamped to +-truncation; the accumulated weight (0 = never
/// observed); the weighted mean colour; flags. 12 bytes, so a block of 8^3 voxels is 6 KiB.
struct TsdfVoxel {
  /// flags' bits 1-2: passes(), the updates in a row (up to kMaxPasses) whose ray passed
  /// through the voxel (its depth beyond it by more than the truncation and the depth's noise,
  /// or a carving along the ray); any other update resets the count. A surface whose voxels
  /// behind it were passed again and again was seen to be gone (where a moving object stood),
  /// however much weight it gathered.
  static constexpr int kPassesShift = 1;
  static constexpr int kMaxPasses = 3;
  static constexpr std::uint8_t kPassesMask = kMaxPasses << kPassesShift;
  /// flags' bit 3: reappeared(), a surface was seen in the voxel after rays had passed it (the
  /// gaps of a bush, a door): one pass more does not show that it went, as it does where no ray
  /// had passed before (a car's back, whose inside no ray reached).
  static constexpr std::uint8_t kReappeared = 1 << 3;
  static constexpr std::uint8_t kSavedFlags = kPassesMask | kReappeared;

  float sdf = 0.f;
  float weight = 0.f;
  std::uint8_t r = 0, g = 0, b = 0;
  /// The passes, reappeared, and bits internal to the integrator (its regularization mask, 0 between frames)
  std::uint8_t flags = 0;

  bool observed() const { return weight > 0.f; }
  int passes() const { return (flags & kPassesMask) >> kPassesShift; }
  bool reappeared() const { return flags & kReappeared; }
};

static_assert(sizeof(TsdfVoxel) == 12, "TsdfVoxel is meant to stay 12 bytes");

} // namespace msf
