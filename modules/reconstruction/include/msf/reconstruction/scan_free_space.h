// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>

namespace msf {

/// What one LiDAR scan says is free space, all around the sensor: per direction (bins of 0.4
/// degrees of azimuth by 0.5 of elevation, about the spacing of a 64-ring scanner's rings),
/// the nearest return in the bin and its 8 neighbours. A point nearer than that, in a bin that
/// holds a return, lies in front of every return around its direction: the laser passed
/// through it. A bin without a return (sky, glass, black paint) says nothing. A return that lies
/// more than kBelowGroundM under the ground the scan stands on (the largest plane below the
/// sensor, near level) frees its beam only down to the ground: it may be a beam a wet road or a
/// car's body mirrored on to something else, whose range is the length of its bent path, and
/// taken whole it would clear the road from underneath. A road falling away in the distance
/// loses nothing within the carving's reach.
///
/// The camera sees a quarter of what the LiDAR sees; TsdfIntegrator::carveWithScan uses the
/// rest, and the pixels where the camera has no depth, to clear what moved away (an oncoming car
/// that passed, the old places of a car ahead).
/// (pcl::RangeImageSpherical keeps the nearest return per cell too, but its lookups and its
/// construction are several times slower, and the 3 x 3 minimum is what a lookup needs.)
class ScanFreeSpace {
public:
  static constexpr float kAzimuthBinDeg = 0.4f, kElevationBinDeg = 0.5f;
  static constexpr float kMinElevationDeg = -30.f, kMaxElevationDeg = 15.f;

  /// How far a swept scan's returns may lie from where its one pose puts them: a spinning LiDAR's
  /// sweep is not motion-compensated (KITTI's are not), and at 13 m/s it skews by up to 0.65 m.
  static constexpr float kSweepSkewM = 0.6f;
  /// How far under the ground plane a return may lie and still be taken whole: a road that falls
  /// away by a 5 % grade over the carving's reach, a kerb, a ditch's edge.
  static constexpr float kBelowGroundM = 1.0f;

  ScanFreeSpace() = default;
  /// From the returns of one scan, in the sensor's frame (x forward, z up); non-finite points
  /// and points at the sensor are skipped. `swept`: taken by a spinning LiDAR over its period
  /// (the rig's lidar.sweeping), false for a scan of one instant.
  explicit ScanFreeSpace(const pcl::PointCloud<pcl::PointXYZI>& scan, bool swept = true);

  bool empty() const { return nearest_.empty(); }
  /// How far a return may lie from where the scan's pose puts it: kSweepSkewM for a swept scan,
  /// 0 for one taken at one instant.
  float skew() const { return skew_m_; }
  /// The returns more than kBelowGroundM under the ground plane, whose beams end at it (0 where
  /// the scan shows no ground).
  std::size_t belowGround() const { return below_ground_; }
  /// The nearest return around the direction of `p` (sensor frame), or 0 where the direction's
  /// own bin holds no return or lies outside the elevations kept.
  float nearestAround(const Eigen::Vector3f& p) const;

private:
  cv::Mat nearest_; // CV_32FC1, elevation rows x azimuth columns, 0 = nothing known
  float skew_m_ = kSweepSkewM;
  std::size_t below_ground_ = 0;
};

} // namespace msf
