// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

namespace msf {

/// Section `rings` of a config file: which rings of a scan are held out as ground truth
/// (evaluation protocol 2, docs/design.md).
struct RingSplitConfig {
  static constexpr const char* kSection = "rings";
  static constexpr const char* kAbout =
      "the ring hold-out of evaluation protocols 2 and 4 (msf_holdout, msf_reconstruct -holdout)";
  int modulo = 4;
  int heldout_remainder = 2;

  template <class Keys>
  void keys(Keys& k) {
    k("modulo", modulo, atLeast(2), "rings with id % modulo == heldout_remainder are held out as ground truth");
    k("heldout_remainder", heldout_remainder, atLeast(0), "the remainder of the held-out rings' ids (below modulo)");
  }
  /// Throws ConfigError naming the key out of range.
  void validate() const;
  bool isHeldOut(int ring) const { return ring % modulo == heldout_remainder; }
};

/// Ring id of each point of a scan in file order: the number of azimuth wraps before it, a
/// wrap being atan2(y, x) dropping by more than pi from one point to the next. On KITTI a
/// laser's sweep starts and ends straight ahead, so a full scan has 64 wraps (ids 0..64) and
/// an id holds the left half (azimuth > 0) of one laser and the right half of the one before.
std::vector<int> ringIds(const pcl::PointCloud<pcl::PointXYZI>& scan);

/// Ring id of each point from its elevation above the sensor's horizontal plane: the index of
/// the nearest of the beams' elevations (degrees, lowest beam first), for a LiDAR whose points
/// carry no ring and are not stored ring after ring.
std::vector<int> ringIdsFromElevations(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                       const std::vector<double>& elevations_deg);

/// Splits a scan (file order) into the points of input rings and of held-out rings, both in
/// file order; headers are copied. Returns the number of ring ids (wraps + 1).
/// Throws ConfigError for an invalid config.
int splitRings(const pcl::PointCloud<pcl::PointXYZI>& scan, const RingSplitConfig& config,
               pcl::PointCloud<pcl::PointXYZI>& input, pcl::PointCloud<pcl::PointXYZI>& heldout);

/// The same with each point's ring id given (from the data, or ringIdsFromElevations); returns
/// the number of ring ids (the largest + 1). Throws InvalidInputError when the ids are not one
/// per point.
int splitRings(const pcl::PointCloud<pcl::PointXYZI>& scan, const std::vector<int>& ids, const RingSplitConfig& config,
               pcl::PointCloud<pcl::PointXYZI>& input, pcl::PointCloud<pcl::PointXYZI>& heldout);

} // namespace msf
