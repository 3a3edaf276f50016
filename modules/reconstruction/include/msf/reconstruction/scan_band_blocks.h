// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/tsdf_block.h>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <unordered_set>
#include <vector>

namespace msf {

/// The blocks of a TsdfVolume (TsdfBlock::kSide voxels a side) within the truncation band of a
/// LiDAR scan's returns that a camera sees, found from the scans and their poses alone: the
/// surfaces a run integrates, where BlockFootprint holds the whole space its views cross. The
/// union over scans grows with the surface seen, as the volume does; the blocks the fused depth
/// adds between and beyond the returns (interpolated rows, stereo above the LiDAR's beams) are a
/// share of them that Reconstructor::predictMemory measures on a few frames.
class ScanBandBlocks {
public:
  /// `voxel_size_m` > 0; each return's band reaches `band_m` >= 0 along its ray either side;
  /// returns count between depths near_m and far_m along the camera's optical axis.
  ScanBandBlocks(double voxel_size_m, double band_m, double near_m, double far_m);

  /// Adds the blocks of the returns of `scan` (LiDAR frame) that land in `camera`'s image,
  /// placed by T_cam_lidar and T_world_cam. Throws InvalidInputError for an invalid camera.
  void addScan(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_cam_lidar,
               const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam);

  std::size_t blocks() const { return blocks_.size(); }
  /// Blocks whose box meets the ball of `radius_m` around `centre` (world frame).
  std::size_t blocksWithin(const Eigen::Vector3d& centre, double radius_m) const;

private:
  GridIndex blockOf(const Eigen::Vector3d& p) const;

  double voxel_size_, band_, near_, far_;
  std::unordered_set<GridIndex, GridIndexHash> blocks_;
};

} // namespace msf
