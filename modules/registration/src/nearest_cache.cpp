#include <msf/registration/nearest_cache.h>
#include <msf/registration/voxel_table.h>

#include <cmath>

namespace msf {

NearestCache::NearestCache(const LocalMap& map, double max_distance, std::size_t queries)
    : map_(map), max_distance2_(max_distance * max_distance), max_distance_(max_distance),
      inv_voxel_size_(1.0 / map.voxelSize()), entries_(queries) {}

bool NearestCache::nearest(std::size_t query, const Eigen::Vector3d& p, LocalMap::Neighbor& neighbor) {
  Entry& e = entries_[query];
  const Eigen::Vector3i voxel = voxelOf(p, inv_voxel_size_);
  if (e.reach2 >= 0.0 && (p - e.searched_at).squaredNorm() < e.reach2 && voxel == e.voxel) {
    const double distance2 = (p - e.neighbor.point).squaredNorm();
    // Every other point is farther still, so none is within reach when this one is not.
    if (distance2 >= max_distance2_)
      return false;
    neighbor = e.neighbor;
    neighbor.distance2 = distance2;
    return true;
  }
  ++searches_;
  double clearance2 = 0.0;
  const bool found = map_.nearest(p, max_distance_, e.neighbor, &clearance2);
  e.searched_at = p;
  e.voxel = voxel;
  e.reach2 = -1.0;
  if (found) {
    // A nanometre less, so that rounding never lets a tie through.
    const double reach = 0.5 * (std::sqrt(clearance2) - std::sqrt(e.neighbor.distance2)) - 1e-9;
    if (reach > 0.0)
      e.reach2 = reach * reach;
    neighbor = e.neighbor;
  }
  // Nothing within max_distance: something may come within it with any move, search again.
  return found;
}

} // namespace msf
