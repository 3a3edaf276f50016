// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/point_list.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/registration/voxel_table.h>

#include <cstddef>
#include <memory>
#include <vector>

namespace msf {

/// The local map scans are registered to: world points in a hashed grid of voxels, each
/// holding a few points (not one: the nearest neighbour of a point must be a measured point
/// near it, not a voxel's representative up to half a voxel away), and the plane of every
/// return that fell in the voxel, from all scans (a single scan's rings are lines, not
/// planes, beyond a few metres; successive scans' rings fill the voxel in). Voxels far from
/// the sensor are dropped, so the map follows the drive and its size is bounded.
class LocalMap {
public:
  using Ptr = std::shared_ptr<LocalMap>;
  using ConstPtr = std::shared_ptr<const LocalMap>;

  /// A map point near a query, with the plane of its voxel when the voxel's returns lie on
  /// one: at least 5, spread over a tenth of a voxel in two directions and 7 times less in
  /// the third.
  struct Neighbor {
    Eigen::Vector3d point;
    double distance2 = 0;  ///< squared distance from the query
    bool planar = false;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d plane_point = Eigen::Vector3d::Zero();  ///< the mean of the voxel's returns
  };

  /// Throws InvalidInputError for a voxel size that is not > 0 or fewer than 1 point a voxel.
  LocalMap(double voxel_size, int max_points_per_voxel);

  /// Adds a scan in world coordinates: `points_world` (downsampled) each where its voxel has
  /// room and no point already lies within voxel_size / sqrt(max_points_per_voxel), so a
  /// voxel fills with points spread over it, not with the same spot seen from successive
  /// frames; and the returns each point stands for (`moments`, in world axes, one per point,
  /// or none), to the planes of the points' voxels only.
  void addScan(const PointList& points_world, const std::vector<PointMoments>& moments);
  /// Points only, each its own return.
  void addPoints(const PointList& points_world);
  /// Drops the voxels whose centre is farther than `max_distance` from `origin`.
  void removeFarFrom(const Eigen::Vector3d& origin, double max_distance);
  void clear();

  /// The map point nearest to `p` among the voxels within one voxel of p's and closer than
  /// `max_distance`; false when there is none. With `clearance2`, also the squared distance
  /// from p to the second-nearest of those points (max_distance^2 when there is none that
  /// near), so that a caller knows how far p may move before the answer could change
  /// (NearestCache); the search then prunes with the second-nearest, not the nearest.
  bool nearest(const Eigen::Vector3d& p, double max_distance, Neighbor& neighbor, double* clearance2 = nullptr) const;
  /// Asks the processor to fetch what nearest(p) will look up first (the table's slots of the
  /// 8 voxels nearest to p), for a search a few queries later: the map is larger than the
  /// cache, and a search that waits for memory voxel after voxel is the registration's
  /// largest cost.
  void prefetch(const Eigen::Vector3d& p) const;

  std::size_t size() const { return points_; }
  std::size_t voxelCount() const { return voxels_.size(); }
  bool empty() const { return points_ == 0; }
  double voxelSize() const { return voxel_size_; }
  /// Every point of the map (for pictures and tests).
  PointList points() const;

private:
  // What a search reads of the voxels it looks at is their number of points (counts_, a few
  // tens of kilobytes that stay in the cache) and their points; a Voxel, only for the answer's.
  struct Voxel {
    Eigen::Vector3i index = Eigen::Vector3i::Zero();
    bool fitted = false;  // the plane is that of the voxel's returns (none added since it was fitted)
    bool planar = false;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(), mean = Eigen::Vector3d::Zero();
  };
  // A voxel's returns, about its low corner (small numbers far from the origin).
  struct Moments {
    PointMoments returns;
  };
  const Eigen::Vector3d* voxelPoints(int v) const { return &pool_[static_cast<std::size_t>(v) * max_points_]; }
  int voxelFor(const Eigen::Vector3d& p);  // its index, created when absent
  void rebuildTable();
  void fitPlane(Voxel& voxel, const Moments& moments) const;

  double voxel_size_, inv_voxel_size_, min_spacing2_;
  int max_points_;
  // Mutable for the planes only: a voxel's plane is fitted when a search first answers with
  // one of its points (a scan changes thousands of voxels' returns, and a registration asks
  // for the planes of a few hundred), so nearest() is not to be called from two threads at once.
  mutable std::vector<Voxel> voxels_;
  std::vector<int> counts_;  // points of each voxel, in voxels_' order
  std::vector<Moments> moments_;  // in voxels_' order
  PointList pool_;  // max_points_ slots per voxel, in voxels_' order
  VoxelTable table_;
  VoxelBits occupied_;  // the voxels of table_, for searches to skip empty space
  std::size_t points_ = 0;
};

} // namespace msf
