// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/persistence.hpp>

#include <iosfwd>
#include <string>

namespace msf {

/// How DepthFusion merges the two samples of a pixel (see fusion_model.h).
enum class FusionMethod {
  Paper,       ///< the paper's eq. 6 with dynamic weights
  Uncertainty  ///< inverse-variance fusion with a k-sigma disagreement test
};

/// Which weights eq. 6 multiplies (fusion_model.h, fusePaper).
enum class PaperWeights {
  Relative, ///< w1 = 1, w2 = w_L / w_S: stereo's own weight enters the mean (the project's reading)
  AsWritten ///< w1 = w_S, w2 = w_L as the paper defines them: w1 cancels, only w_L sets the mean
};

/// "relative" or "as_written"; throws ConfigError naming the key and the text otherwise.
PaperWeights parsePaperWeights(const std::string& name);
const char* toString(PaperWeights weights);

/// "paper" or "uncertainty"; throws ConfigError naming the text otherwise.
FusionMethod parseFusionMethod(const std::string& name);
const char* toString(FusionMethod method);

/// What marks an edge in the interpolated LiDAR, for its sigma (lidarEdgeCue).
enum class LidarEdgeCue {
  Bend, ///< the second difference of the disparity: 0 on any plane, the road at any slope
  Range ///< max - min disparity in a window: a plane's slope counts as an edge
};
const char* toString(LidarEdgeCue cue);

/// Every parameter of DepthFusion, read from the `fusion` section of a config file.
/// The defaults were measured on KITTI odometry 04 frames 0-9 under protocol 2
/// (msf_holdout; docs/results.md has the table).
struct DepthFusionConfig {
  FusionMethod method = FusionMethod::Uncertainty;

  // --- paper (eq. 6), see fusion_model.h
  PaperWeights paper_weights = PaperWeights::Relative;
  float paper_lidar_gain = 4.f;               ///< w_L on a real return
  float paper_lidar_distance_px = 8.f;        ///< w_L halves this far from the nearest real return
  float paper_stereo_reference_depth_m = 20.f;///< w_S = confidence where z_stereo <= this, falls as 1/z^2 beyond
  float paper_min_stereo_confidence = 0.05f;  ///< floor of the confidence in w_S

  // --- uncertainty: sigmas of the disparity d = f B / z, in pixels
  float stereo_sigma_min_px = 0.35f;          ///< sigma of a stereo disparity of confidence 1
  float stereo_sigma_max_px = 1.75f;          ///< ... of confidence 0 (quadratic in 1 - confidence between)
  float lidar_sigma_px = 0.1f;                ///< sigma of the LiDAR on a smooth surface at a real return
  float lidar_sigma_per_distance = 0.02f;     ///< growth per pixel of distance to the nearest real return
  float lidar_sigma_per_range = 0.3f;         ///< growth per pixel of the edge cue (lidar_edge_cue)
  LidarEdgeCue lidar_edge_cue = LidarEdgeCue::Bend; ///< bend (step lidar_range_window_px / 2) or range
  /// The range noise of a LiDAR return in metres, for the fused weight (lidarDepthWeight):
  /// the HDL-64E's is under 2 cm; 3 cm leaves room for calibration and timing.
  float lidar_range_sigma_m = 0.03f;
  float disagreement_k_sigma = 3.f;           ///< beyond k sigma the more certain sample wins alone
  int lidar_range_window_px = 5;              ///< odd window of the LiDAR's edge cue
  bool parallax_check = true;                 ///< stereo wins where the LiDAR saw past a foreground edge
  int parallax_max_rows = 16;                 ///< rows below a pixel searched for that foreground

  // --- both methods, last: a fused disparity between the two surfaces of a depth edge takes
  // the nearest real return's (edge_support.h)
  bool edge_support = true;
  int edge_window_rows = 13;                  ///< odd window of real returns (KITTI rings are ~5 rows apart)
  int edge_window_cols = 7;                   ///< odd
  float edge_jump_px = 8.f;                   ///< an edge: the window's returns differ by more (disparity)
  float edge_tolerance_px = 2.f;              ///< a fused disparity this near a return is on its surface

  // --- after both: a LiDAR-backed wall goes on upward where the image stays blank (facade_extension.h)
  bool facade_extension = true;
  float facade_anchor_sigma_m = 0.2f;         ///< anchors: fused pixels known to within this (LiDAR, near stereo)
  float facade_grey_tolerance = 8.f;          ///< grey levels from the anchors' run (5x5 box-filtered image)
  float facade_max_texture = 4.f;             ///< blank: grey levels of standard deviation over 5x5 pixels
  float facade_sigma_per_m = 0.05f;           ///< sigma's growth per metre above the last anchor
  float facade_max_normal_y = 0.3f;           ///< near vertical surfaces only (|n_y| of the unit normal)
  float facade_max_gap_m = 2.5f;              ///< a window's height crossed where stereo sees the wall; 0: none

  /// Overrides the keys present in `node` (the `fusion` section), then validates.
  void read(const cv::FileNode& node);
  /// Throws ConfigError naming the key of the first value out of range.
  void validate() const;
  void print(std::ostream& out) const;
};

} // namespace msf
