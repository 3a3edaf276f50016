// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/registration/point_list.h>
#include <msf/registration/sweep_deskew.h>
#include <msf/registration/voxel_table.h>

#include <Eigen/Core>

#include <vector>

namespace msf {

/// The spread of the points a downsampled point stands for: their count, and the sums of
/// their offsets from it and of the offsets' outer products (upper triangle), in the
/// points' axes. Moments add up, so a map can fit planes to every return it was given
/// from the few points it keeps.
struct PointMoments {
  int count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  /// The same points seen in axes turned by R (the offsets turn, the count stays).
  PointMoments rotated(const Eigen::Matrix3d& R) const;
};

/// One point per voxel of edge `voxel_size`: the first one in `points`' order, a measured
/// point rather than a centroid that lies on no surface at an edge. The order of the kept
/// points is their input order. With `moments`, also the moments of each kept point's voxel
/// about it, in the same order. Throws InvalidInputError for a voxel size that is not > 0.
PointList voxelDownsample(const PointList& points, double voxel_size, std::vector<PointMoments>* moments = nullptr);

/// voxelDownsample into `kept` (and `moments`), with a table kept from call to call: a
/// tracker downsamples 120000 returns a frame, and buffers of that size allocated anew each
/// time cost page faults and zeroing (a tenth of the odometry's time) and contend with the
/// other threads of the process for its memory map. `kept` must not be `points`.
class VoxelDownsampler {
public:
  void downsample(const PointList& points, double voxel_size, PointList& kept,
                  std::vector<PointMoments>* moments = nullptr);
  /// downsample of a raw scan in one pass, without a copy of it: only the finite returns
  /// whose distance from the sensor is in [min_range, max_range], each deskewed by `deskew`
  /// when given (the points and moments of deskewSweep of the returns in range, then
  /// downsample). Returns the number of returns in range.
  std::size_t downsampleScan(const PointList& scan, double min_range, double max_range, const SweepDeskew* deskew,
                             double voxel_size, PointList& kept, std::vector<PointMoments>* moments = nullptr);

private:
  VoxelTable seen_;
};

} // namespace msf
