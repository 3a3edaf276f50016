// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/spatial_hash.h>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <unordered_set>

namespace msf {

/// Where the LiDAR's returns landed over a run: the cells (a grid of `cell_m`, world frame)
/// that hold a return of any frame. A piece of a map with no return near it came from stereo
/// (or the interpolation) alone.
class LidarSupport {
public:
  /// Throws InvalidInputError for a cell that is not > 0.
  explicit LidarSupport(double cell_m);

  /// The finite returns of `scan` (the LiDAR's frame; none at its origin) placed in the world by `T_world_lidar`.
  void addScan(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_lidar);
  void addPoint(const Eigen::Vector3f& world);
  /// Whether a return lies in the cell of `p` or one of its 26 neighbours: every return within
  /// a cell of p counts, none farther than 2 sqrt(3) cells.
  bool supports(const Eigen::Vector3f& p) const;

  std::size_t cells() const { return cells_.size(); }
  double cellSize() const { return cell_; }

private:
  struct CellEqual {
    bool operator()(const Eigen::Vector3i& a, const Eigen::Vector3i& b) const { return a == b; }
  };
  Eigen::Vector3i cellOf(const Eigen::Vector3f& p) const;

  float cell_;
  std::unordered_set<Eigen::Vector3i, CellHash, CellEqual> cells_;
};

} // namespace msf
