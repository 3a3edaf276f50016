// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/registration/nearest_cache.h>
#include <msf/registration/voxel_table.h>

#include <cmath>
#include <limits>

namespace msf {

void NearestCache::reset(const LocalMap& map, double max_distance, std::size_t queries) {
  map_ = &map;
  max_distance_ = max_distance;
  max_distance2_ = max_distance * max_distance;
  inv_voxel_size_ = 1.0 / map.voxelSize();
  entries_.assign(queries, Entry{});
  searches_ = 0;
}

bool NearestCache::nearest(std::size_t query, const Eigen::Vector3d& p, LocalMap::Neighbor& neighbor) {
  Entry& e = entries_[query];
  const Eigen::Vector3i voxel = voxelOf(p, inv_voxel_size_);
  if ((p - e.searched_at).squaredNorm() < e.reach2 && voxel == e.voxel) {
    if (!e.within)
      return false;
    const double distance2 = (p - e.neighbor.point).squaredNorm();
    // Every other point is farther still, so none is within reach when this one is not.
    if (distance2 >= max_distance2_)
      return false;
    neighbor = e.neighbor;
    neighbor.distance2 = distance2;
    return true;
  }
  ++searches_;
  // Without a limit, so that a query with nothing within max_distance knows how far it is
  // from being within it (the search prunes nothing more: 27 voxels reach a voxel or more).
  double clearance2 = 0.0;
  const bool any = map_->nearest(p, std::numeric_limits<double>::infinity(), e.neighbor, &clearance2);
  e.searched_at = p;
  e.voxel = voxel;
  e.within = any && e.neighbor.distance2 < max_distance2_;
  // A nanometre less, so that rounding never lets a tie through.
  double reach = std::numeric_limits<double>::infinity(); // no point around: none while in this voxel
  if (e.within)
    reach = 0.5 * (std::sqrt(clearance2) - std::sqrt(e.neighbor.distance2)) - 1e-9;
  else if (any)
    reach = std::sqrt(e.neighbor.distance2) - max_distance_ - 1e-9; // every point stays beyond max_distance
  e.reach2 = reach > 0.0 ? reach * reach : -1.0;
  if (e.within)
    neighbor = e.neighbor;
  return e.within;
}

} // namespace msf
