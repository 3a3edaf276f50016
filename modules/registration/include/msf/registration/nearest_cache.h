// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/local_map.h>

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace msf {

/// LocalMap::nearest for queries that move a little between calls, as a scan's points do
/// between the iterations of an ICP (after the first, by millimetres). Each query remembers
/// its last answer and its clearance, the distance c to the second-nearest map point; while
/// it moves by m < (c - d) / 2 from where it was searched (d: the distance to its nearest),
/// no other point can have come nearer than that one (d + m < c - m), and while it stays in
/// the same voxel the searched voxels are the same: the answer is the map's, without a search.
/// A query with no map point within max_distance, the nearest at D, has none while it moves
/// by less than D - max_distance, and none at all while it stays in a voxel whose neighbours
/// are empty. Beyond that it searches again. The map must not change between the calls.
class NearestCache {
public:
  NearestCache() = default;
  /// For queries 0 .. queries - 1, each within `max_distance` (LocalMap::nearest's).
  NearestCache(const LocalMap& map, double max_distance, std::size_t queries) { reset(map, max_distance, queries); }
  /// Forgets every answer, for a new map or new queries; keeps the memory.
  void reset(const LocalMap& map, double max_distance, std::size_t queries);

  /// LocalMap::nearest(p, max_distance, neighbor) for query `query` now at `p`.
  bool nearest(std::size_t query, const Eigen::Vector3d& p, LocalMap::Neighbor& neighbor);

  /// For a call nearest(query, p, ...) a few queries later: LocalMap::prefetch(p) when that
  /// call will search the map.
  void prefetch(std::size_t query, const Eigen::Vector3d& p) const {
    const Entry& e = entries_[query];
    if (!((p - e.searched_at).squaredNorm() < e.reach2))
      map_->prefetch(p);
  }

  /// Calls that searched the map (the others reused an answer).
  std::size_t searches() const { return searches_; }

private:
  struct Entry {
    Eigen::Vector3d searched_at = Eigen::Vector3d::Zero();
    Eigen::Vector3i voxel = Eigen::Vector3i::Zero();
    double reach2 = -1.0;  // squared distance it may move from searched_at; < 0: search
    bool within = false;   // `neighbor` is within max_distance
    LocalMap::Neighbor neighbor;
  };

  const LocalMap* map_ = nullptr;
  double max_distance2_ = 0, max_distance_ = 0, inv_voxel_size_ = 1;
  std::vector<Entry> entries_;
  std::size_t searches_ = 0;
};

} // namespace msf
