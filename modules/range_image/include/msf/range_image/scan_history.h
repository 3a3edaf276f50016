// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/io/calibration.h>
#include <msf/range_image/lidar_projector.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <deque>
#include <memory>

namespace msf {

/// Section `accumulation`: earlier scans carried into the current view (ScanHistory).
struct ScanHistoryConfig {
  static constexpr const char* kSection = "accumulation";
  static constexpr const char* kAbout =
      "earlier scans carried into the current camera by the poses, where the current rings agree with them";
  /// Off by default: on KITTI's shared frames the earlier scans leave the fused depth's D1 where
  /// the frame's own scan puts it and cost a projection per scan (docs/results.md, "Earlier scans
  /// in the current view"). With them, 2: the current rings are 4-7 px apart in KITTI's image and
  /// a scan a frame or two earlier, a metre or two behind, meets the same surfaces between them;
  /// older scans add little the newer ones lack, and their pose error grows.
  int scans = 0;
  /// An earlier return is used where it lies within the depths of the current returns that bracket
  /// it (the nearest rows above and below with a return, within window_*), widened by this
  /// tolerance, the relative one and three times its pose error.
  float agreement_m = 0.1f;
  float agreement_rel = 0.02f;
  int window_rows_px = 8;
  int window_cols_px = 2;
  /// The relative pose's error per frame of age: in position, and in heading (at a return's range).
  float translation_sigma_m = 0.02f;
  float rotation_sigma_deg = 0.02f;

  template <class Keys>
  void keys(Keys& k) {
    k("scans", scans, between(0, 16), "earlier scans carried into the current view (0: the current scan alone)");
    k("agreement_m", agreement_m, atLeast(0), "how far beyond the bracketing current returns' depths an earlier "
                                              "return may lie, m");
    k("agreement_rel", agreement_rel, atLeast(0), "the same, relative to the earlier return's depth");
    k("window_rows_px", window_rows_px, between(1, 64),
      "rows above and below searched for the current returns that bracket an earlier one, px");
    k("window_cols_px", window_cols_px, between(0, 16), "columns to each side searched with them, px");
    k("translation_sigma_m", translation_sigma_m, atLeast(0), "error of the relative pose per frame of age, m");
    k("rotation_sigma_deg", rotation_sigma_deg, atLeast(0), "error of the relative heading per frame of age, deg");
  }
  /// Throws ConfigError naming the first key out of range.
  void validate() const;
};

/// Earlier scans in the current view: the last `scans` scans, each with its LiDAR pose, carried
/// into the current scan's frame and projected onto the canvas of LidarProjector. An earlier
/// return is added to the current scan only between the current rings and only where the current
/// returns bracket it: within the depths of the nearest current returns above and below it
/// (widened by the tolerance and its pose error), so a return hidden behind a nearer surface from
/// the current view (it lies beyond both) and a return of an object that has moved (it lies in
/// front of both, in free space the current scan sees through) are left out, and a return with
/// no current return around it (above the top ring) adds nothing unverified. Pixels with a current
/// return keep it. The history holds what it is given: under a ring hold-out, the input rings only.
///
/// Scans are taken as they are, not deskewed: a static point seen by two sweeps at nearly the
/// same azimuth carries nearly the same motion distortion in both, so the relative pose places it
/// where the current (raw) scan would see it; the projection uses the current scan raw too.
///
///   msf::ScanHistory history(calibration, config.projection, config.accumulation);
///   history.densify(scan, T_world_velo, dense_scan);   // scan + agreeing earlier returns
///   lidar.computeDepth(dense_scan, depth, &distance);  // then interpolated as one scan
///
/// Not thread-safe: one object per sequence, frames in order.
class ScanHistory {
public:
  using Ptr = std::shared_ptr<ScanHistory>;

  /// What the last densify() did.
  struct Stats {
    std::size_t earlier_in_view = 0;  ///< earlier returns that landed on the canvas (after the z-buffer)
    std::size_t on_current = 0;       ///< of them, on or next to a pixel of a current return
    std::size_t unbracketed = 0;      ///< with no current return above or below within the window
    std::size_t disagreeing = 0;      ///< beyond the bracketing depths: hidden, or moved
    std::size_t added = 0;            ///< added to the current scan
  };

  /// Throws CalibrationError or ConfigError naming what is wrong.
  ScanHistory(const Calibration& calibration, const ProjectionConfig& projection, const ScanHistoryConfig& config);

  /// `scan` (the LiDAR frame at pose T_world_velo) with the agreeing returns of the earlier scans
  /// appended, into `out` (not `scan`); then `scan` joins the history and the oldest beyond
  /// `scans` leaves it.
  void densify(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_velo,
               pcl::PointCloud<pcl::PointXYZI>& out);

  /// What step 1 interpolates: `scan` with the earlier scans' agreeing returns (densify) when
  /// `scans` > 0 and the frame has its pose T_world_velo; else `scan` itself, and a frame without
  /// a pose clears the history (earlier scans cannot be placed). Valid until the next call.
  const pcl::PointCloud<pcl::PointXYZI>& withEarlierScans(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                                          const Eigen::Isometry3d* T_world_velo);
  /// Forgets every earlier scan (a jump in the poses, a new sequence).
  void clear() { scans_.clear(); }
  /// The earlier scans held, newest first, each in its own LiDAR frame.
  std::size_t size() const { return scans_.size(); }
  const pcl::PointCloud<pcl::PointXYZI>& scan(std::size_t age_minus_one) const {
    return *scans_[age_minus_one].points;
  }
  const ScanHistoryConfig& config() const { return config_; }
  const Stats& lastStats() const { return stats_; }

private:
  struct Entry {
    pcl::PointCloud<pcl::PointXYZI>::Ptr points;  // in front of the LiDAR, its own frame
    Eigen::Isometry3d T_world_velo;
  };
  /// Adds to `out` the returns of `earlier` (age in frames) that agree with the current canvas.
  void addAgreeing(const Entry& earlier, int age, const Eigen::Isometry3d& T_velo_world,
                   pcl::PointCloud<pcl::PointXYZI>& out);
  /// The depths of the current returns nearest above and below (u, v) within the window: false
  /// when either side has none.
  bool bracket(int u, int v, float& nearest, float& farthest) const;
  void remember(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_velo);

  ScanHistoryConfig config_;
  LidarProjector projector_;
  Eigen::Isometry3d T_velo_cam_;  // of the projector's camera
  std::deque<Entry> scans_;
  cv::Mat current_;                              // canvas depth of the current scan
  cv::Mat added_;                                // canvas depth of the earlier returns added
  pcl::PointCloud<pcl::PointXYZI> moved_;        // an earlier scan in the current frame
  pcl::PointCloud<pcl::PointXYZI> organized_;    // its nearest return per canvas pixel, camera frame
  pcl::PointCloud<pcl::PointXYZI> dense_;        // withEarlierScans' result
  Stats stats_;
};

} // namespace msf
