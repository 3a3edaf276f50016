// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Two TSDF stores (msf::TsdfStore) compared voxel by voxel: what the merge's tests measure.
#include <msf/reconstruction/tsdf_store.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <tuple>

namespace msf::test {

using BlockMap = std::map<std::tuple<int, int, int>, TsdfBlock>;

/// Every block of a store, by its index.
inline BlockMap blocksOf(const TsdfStore& store) {
  BlockMap blocks;
  for (const GridIndex& t : store.tiles())
    store.readTile(t, [&](const TsdfBlock& b) { blocks[{b.index.x(), b.index.y(), b.index.z()}] = b; });
  return blocks;
}

/// The largest differences between two stores' observed voxels.
struct StoreDifference {
  bool same_blocks = true;      ///< the same blocks, and the same voxels observed in them
  double sdf = 0;               ///< metres
  double weight_relative = 0;
  int colour = 0;               ///< grey levels
  std::size_t observed = 0;     ///< voxels compared
  std::size_t colour_off = 0;   ///< of which a channel differs by more than 2 grey levels
  double colour_mean = 0;       ///< the mean of the largest channel difference, grey levels
};

inline StoreDifference compareStores(const TsdfStore& a, const TsdfStore& b) {
  const BlockMap ba = blocksOf(a), bb = blocksOf(b);
  StoreDifference d;
  d.same_blocks = ba.size() == bb.size();
  for (const auto& [key, block] : ba) {
    const auto it = bb.find(key);
    if (it == bb.end()) {
      d.same_blocks = false;
      continue;
    }
    for (int i = 0; i < TsdfBlock::kVoxels; ++i) {
      const TsdfVoxel &u = block.voxels[i], &v = it->second.voxels[i];
      if ((u.weight > 0) != (v.weight > 0))
        d.same_blocks = false;
      if (!(u.weight > 0) || !(v.weight > 0))
        continue;
      ++d.observed;
      d.sdf = std::max(d.sdf, static_cast<double>(std::abs(u.sdf - v.sdf)));
      d.weight_relative = std::max(d.weight_relative, std::abs(u.weight - v.weight) / static_cast<double>(v.weight));
      const int colour = std::max({std::abs(u.r - v.r), std::abs(u.g - v.g), std::abs(u.b - v.b)});
      d.colour = std::max(d.colour, colour);
      d.colour_off += colour > 2 ? 1 : 0;
      d.colour_mean += colour;
    }
  }
  d.colour_mean /= std::max<std::size_t>(d.observed, 1);
  return d;
}

} // namespace msf::test
