// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace msf {

/// The blocks of a TsdfVolume (TsdfBlock::kSide voxels a side) that depth frames seen from
/// known poses can allocate, found before their depth is read: TsdfIntegrator allocates a
/// frame's blocks only along its pixels' rays, between min_depth_m and allocationDepth() along
/// the optical axis, so they all meet that view frustum. The union over frames of the blocks
/// that meet each frustum (grown by a voxel against rounding) is an upper bound on what the
/// frames allocate: it holds the free space a frame sees through as well as its surfaces, so it
/// is tight for a few frames and grows with the volume swept rather than the surface seen.
///
/// Stored as runs of blocks along one axis per column of the other two (the axis of the first
/// view's largest extent), so that a view costs a few thousand columns, not its blocks.
class BlockFootprint {
public:
  /// `voxel_size_m`: the volume's voxel (> 0).
  explicit BlockFootprint(double voxel_size_m);

  /// Adds the blocks that meet the view of `camera` from T_world_cam (camera to world) between
  /// depths near_m and far_m along its optical axis, its pixels' edges on the image border.
  /// Throws InvalidInputError when the camera is not valid, the depths are not
  /// 0 <= near_m < far_m, finite, or the view reaches beyond 1e7 m.
  void addView(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, double near_m, double far_m);

  /// Blocks in the footprint. A view that spans more than 2^24 columns of blocks (blocks too
  /// small for its depth) is not listed: its bounding box's blocks are counted instead, in
  /// blocks() and in every blocksWithin(), and contains() does not see them.
  std::size_t blocks() const;
  /// Whether the block of block coordinates `block` (TsdfBlock::index) is in it.
  bool contains(const Eigen::Vector3i& block) const;
  /// Blocks of the footprint that meet the ball of `radius_m` around `centre` (world frame).
  std::size_t blocksWithin(const Eigen::Vector3d& centre, double radius_m) const;

private:
  /// Inclusive runs [first, last] of block indices along axis_, sorted and disjoint.
  using Runs = std::vector<std::pair<int, int>>;
  void addRun(std::uint64_t column, int first, int last);
  /// The block index of coordinate p (metres) on the grid (voxel centres at multiples of vs).
  int blockOf(double p) const;
  static std::uint64_t columnKey(int a, int b) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 | static_cast<std::uint32_t>(b);
  }

  double voxel_size_;
  int axis_ = -1; ///< the axis along which runs lie; the columns are the other two
  std::unordered_map<std::uint64_t, Runs> columns_;
  std::size_t blocks_ = 0;
  double unlisted_ = 0; ///< blocks of views too large to list (their bounding boxes)
};

} // namespace msf
