// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/registration/local_map.h>
#include <msf/registration/plane_fit.h>

#include <array>
#include <cmath>
#include <string>

namespace msf {

LocalMap::LocalMap(double voxel_size, int max_points_per_voxel)
    : voxel_size_(voxel_size), inv_voxel_size_(1.0 / voxel_size), max_points_(max_points_per_voxel) {
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw InvalidInputError("local map: voxel size must be > 0, got " + std::to_string(voxel_size));
  if (max_points_per_voxel < 1)
    throw InvalidInputError("local map: max points per voxel must be >= 1, got " + std::to_string(max_points_per_voxel));
  const double spacing = voxel_size / std::sqrt(static_cast<double>(max_points_per_voxel));
  min_spacing2_ = spacing * spacing;
}

int LocalMap::voxelFor(const Eigen::Vector3d& p) {
  const Eigen::Vector3i index = voxelOf(p, inv_voxel_size_);
  const auto [v, inserted] = table_.insert(voxelKey(index), static_cast<int>(voxels_.size()));
  if (inserted) {
    if (voxels_.size() + 1 > occupied_.capacity()) {
      occupied_.reset(2 * (voxels_.size() + 1));
      for (const Voxel& other : voxels_)
        occupied_.set(voxelKey(other.index));
    }
    occupied_.set(voxelKey(index));
    Voxel voxel;
    voxel.index = index;
    voxels_.push_back(voxel);
    counts_.push_back(0);
    moments_.emplace_back();
    pool_.resize(voxels_.size() * static_cast<std::size_t>(max_points_));
  }
  return v;
}

void LocalMap::addPoints(const PointList& points_world) {
  std::vector<PointMoments> moments(points_world.size());
  for (auto& m : moments)
    m.count = 1;
  addScan(points_world, moments);
}

void LocalMap::addScan(const PointList& points_world, const std::vector<PointMoments>& moments) {
  if (!moments.empty() && moments.size() != points_world.size())
    throw InvalidInputError("local map: " + std::to_string(moments.size()) + " moments for " +
                            std::to_string(points_world.size()) + " points");
  // The table's slot of the point kAhead places on is fetched while this one is added: a
  // scan's voxels are all over a table larger than the cache.
  constexpr std::size_t kAhead = 16;
  for (std::size_t i = 0; i < points_world.size(); ++i) {
    if (i + kAhead < points_world.size())
      table_.prefetch(voxelKey(voxelOf(points_world[i + kAhead], inv_voxel_size_)));
    const Eigen::Vector3d& p = points_world[i];
    const int v = voxelFor(p);
    Voxel& voxel = voxels_[static_cast<std::size_t>(v)];
    if (!moments.empty()) {
      // The point's returns, moved from offsets about the point to offsets about the corner.
      const PointMoments& in = moments[i];
      Moments& m = moments_[static_cast<std::size_t>(v)];
      const Eigen::Vector3d d = p - voxel.index.cast<double>() * voxel_size_;
      const Eigen::Matrix3d cross = d * in.sum.transpose();
      m.returns.count += in.count;
      m.returns.sum += in.count * d + in.sum;
      m.returns.outer += in.count * d * d.transpose() + cross + cross.transpose() +
                         Eigen::Matrix3d(in.outer.selfadjointView<Eigen::Upper>());
      voxel.fitted = false; // fitted again when a search first needs the plane
    }
    int& count = counts_[static_cast<std::size_t>(v)];
    if (count >= max_points_)
      continue;
    Eigen::Vector3d* slots = &pool_[static_cast<std::size_t>(v) * max_points_];
    bool crowded = false;
    for (int k = 0; k < count && !crowded; ++k)
      crowded = (slots[k] - p).squaredNorm() < min_spacing2_;
    if (crowded)
      continue;
    slots[count++] = p;
    ++points_;
  }
}

void LocalMap::fitPlane(Voxel& voxel, const Moments& moments) const {
  PlaneFit plane;
  voxel.fitted = true;
  voxel.planar = msf::fitPlane(moments.returns, 0.1 * voxel_size_, plane);
  if (!voxel.planar)
    return;
  voxel.normal = plane.normal;
  voxel.mean = plane.mean + voxel.index.cast<double>() * voxel_size_;
}

void LocalMap::removeFarFrom(const Eigen::Vector3d& origin, double max_distance) {
  const double max2 = max_distance * max_distance;
  std::size_t kept = 0;
  points_ = 0;
  const auto per_voxel = static_cast<std::size_t>(max_points_);
  for (std::size_t v = 0; v < voxels_.size(); ++v) {
    const Eigen::Vector3d centre = (voxels_[v].index.cast<double>() + Eigen::Vector3d::Constant(0.5)) * voxel_size_;
    if ((centre - origin).squaredNorm() > max2)
      continue;
    if (kept != v) {
      voxels_[kept] = voxels_[v];
      counts_[kept] = counts_[v];
      moments_[kept] = moments_[v];
      std::copy_n(pool_.begin() + static_cast<std::ptrdiff_t>(v * per_voxel), counts_[v],
                  pool_.begin() + static_cast<std::ptrdiff_t>(kept * per_voxel));
    }
    points_ += static_cast<std::size_t>(counts_[kept]);
    ++kept;
  }
  if (kept == voxels_.size())
    return;
  voxels_.resize(kept);
  counts_.resize(kept);
  moments_.resize(kept);
  pool_.resize(kept * per_voxel);
  rebuildTable();
}

void LocalMap::clear() {
  voxels_.clear();
  counts_.clear();
  moments_.clear();
  pool_.clear();
  table_.clear();
  occupied_.reset(0);
  points_ = 0;
}

void LocalMap::rebuildTable() {
  table_.clear();
  table_.reserve(voxels_.size());
  occupied_.reset(2 * voxels_.size());
  for (std::size_t v = 0; v < voxels_.size(); ++v) {
    table_.insert(voxelKey(voxels_[v].index), static_cast<int>(v));
    occupied_.set(voxelKey(voxels_[v].index));
  }
}

namespace {

// Own voxel, then the 6 sharing a face, the 12 sharing an edge, the 8 sharing a corner:
// nearest boxes first, so the best distance shrinks early and prunes the rest.
const std::array<Eigen::Vector3i, 27>& searchOrder() {
  static const std::array<Eigen::Vector3i, 27> order = [] {
    std::array<Eigen::Vector3i, 27> o;
    int k = 0;
    for (int axes = 0; axes <= 3; ++axes)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            if ((dx != 0) + (dy != 0) + (dz != 0) == axes)
              o[static_cast<std::size_t>(k++)] = Eigen::Vector3i(dx, dy, dz);
    return o;
  }();
  return order;
}

} // namespace

bool LocalMap::nearest(const Eigen::Vector3d& p, double max_distance, Neighbor& neighbor, double* clearance2) const {
  const Eigen::Vector3i centre = voxelOf(p, inv_voxel_size_);
  // Where p lies in its voxel, to skip neighbours whose nearest face is already farther than
  // the best point found (the second best, for a clearance): p's own voxel first, then its
  // 26 neighbours.
  const Eigen::Vector3d low = centre.cast<double>() * voxel_size_;
  const Eigen::Vector3d to_low = p - low, to_high = low + Eigen::Vector3d::Constant(voxel_size_) - p;
  double best = max_distance * max_distance, second = best;
  const double& bound = clearance2 ? second : best;  // what a voxel must be nearer than to be searched
  const Eigen::Vector3d* best_point = nullptr;
  int best_voxel = VoxelTable::kAbsent;
  for (const Eigen::Vector3i& offset : searchOrder()) {
    double gap2 = 0.0; // squared distance from p to the neighbour's box
    for (int a = 0; a < 3; ++a) {
      const double gap = offset[a] < 0 ? to_low[a] : offset[a] > 0 ? to_high[a] : 0.0;
      gap2 += gap * gap;
    }
    if (gap2 >= bound)
      continue;
    const std::uint64_t key = voxelKey(centre + offset);
    if (!occupied_.test(key)) // empty space, without a look-up in the table
      continue;
    const int v = table_.find(key);
    if (v == VoxelTable::kAbsent)
      continue;
    const Eigen::Vector3d* pts = voxelPoints(v);
    for (int k = 0, count = counts_[static_cast<std::size_t>(v)]; k < count; ++k) {
      const double d2 = (pts[k] - p).squaredNorm();
      if (d2 < best) {
        second = best;
        best = d2;
        best_point = &pts[k];
        if (best_voxel != v) {
          best_voxel = v;
          __builtin_prefetch(&voxels_[static_cast<std::size_t>(v)]); // its plane, read at the end
        }
      } else if (d2 < second) {
        second = d2;
      }
    }
  }
  if (clearance2)
    *clearance2 = second;
  if (!best_point)
    return false;
  Voxel& voxel = voxels_[static_cast<std::size_t>(best_voxel)];
  if (!voxel.fitted)
    fitPlane(voxel, moments_[static_cast<std::size_t>(best_voxel)]);
  neighbor.point = *best_point;
  neighbor.distance2 = best;
  neighbor.planar = voxel.planar;
  neighbor.normal = voxel.normal;
  neighbor.plane_point = voxel.mean;
  return true;
}

void LocalMap::prefetch(const Eigen::Vector3d& p) const {
  const Eigen::Vector3i centre = voxelOf(p, inv_voxel_size_);
  // The 2 x 2 x 2 voxels around the corner of p's voxel nearest to p: those within half a voxel.
  Eigen::Vector3i step;
  for (int a = 0; a < 3; ++a)
    step[a] = p[a] - centre[a] * voxel_size_ < 0.5 * voxel_size_ ? -1 : 1;
  for (int dx = 0; dx < 2; ++dx)
    for (int dy = 0; dy < 2; ++dy)
      for (int dz = 0; dz < 2; ++dz) {
        const std::uint64_t key = voxelKey(centre + Eigen::Vector3i(dx * step.x(), dy * step.y(), dz * step.z()));
        if (occupied_.test(key))
          table_.prefetch(key);
      }
}

PointList LocalMap::points() const {
  PointList all;
  all.reserve(points_);
  for (std::size_t v = 0; v < voxels_.size(); ++v)
    all.insert(all.end(), voxelPoints(static_cast<int>(v)), voxelPoints(static_cast<int>(v)) + counts_[v]);
  return all;
}

} // namespace msf
