// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <string>

namespace msf {

/// How DepthFusion merges the two samples of a pixel (see fusion_model.h).
enum class FusionMethod {
  Paper,       ///< the paper's eq. 6 with dynamic weights
  Uncertainty  ///< inverse-variance fusion with a k-sigma disagreement test
};
inline constexpr Choice<FusionMethod> kFusionMethods[] = {{"uncertainty", FusionMethod::Uncertainty},
                                                          {"paper", FusionMethod::Paper}};

/// Which weights eq. 6 multiplies (fusion_model.h, fusePaper).
enum class PaperWeights {
  Relative, ///< w1 = 1, w2 = w_L / w_S: stereo's own weight enters the mean (the project's reading)
  AsWritten ///< w1 = w_S, w2 = w_L as the paper defines them: w1 cancels, only w_L sets the mean
};
inline constexpr Choice<PaperWeights> kPaperWeights[] = {{"relative", PaperWeights::Relative},
                                                         {"as_written", PaperWeights::AsWritten}};

/// What marks an edge in the interpolated LiDAR, for its sigma (lidarEdgeCue).
enum class LidarEdgeCue {
  Bend, ///< the second difference of the disparity: 0 on any plane, the road at any slope
  Range ///< max - min disparity in a window: a plane's slope counts as an edge
};
inline constexpr Choice<LidarEdgeCue> kLidarEdgeCues[] = {{"bend", LidarEdgeCue::Bend}, {"range", LidarEdgeCue::Range}};

/// "paper" or "uncertainty"; throws ConfigError naming the text otherwise.
FusionMethod parseFusionMethod(const std::string& name);
const char* toString(FusionMethod method);
const char* toString(PaperWeights weights);
const char* toString(LidarEdgeCue cue);

/// Every parameter of DepthFusion: section `fusion` of a config file. The defaults are chosen
/// under protocol 2 (msf_holdout; docs/results.md).
struct DepthFusionConfig {
  static constexpr const char* kSection = "fusion";
  static constexpr const char* kAbout =
      "DepthFusion (paper step 4): per-pixel fusion of the interpolated LiDAR and stereo";
  FusionMethod method = FusionMethod::Uncertainty;

  // paper (eq. 6), see fusion_model.h: w_L = gain / (1 + distance / distance_px),
  // w_S = max(confidence, min) * min(1, (z_ref / z)^2)
  PaperWeights paper_weights = PaperWeights::Relative;
  float paper_lidar_gain = 4.f;
  float paper_lidar_distance_px = 8.f;
  float paper_stereo_reference_depth_m = 20.f;
  float paper_min_stereo_confidence = 0.05f;

  // uncertainty: sigmas of the disparity d = f B / z, in pixels
  float stereo_sigma_min_px = 0.35f;
  float stereo_sigma_max_px = 1.75f;
  float lidar_sigma_px = 0.1f;
  float lidar_sigma_per_distance = 0.02f;
  float lidar_sigma_per_range = 0.3f;
  LidarEdgeCue lidar_edge_cue = LidarEdgeCue::Bend;
  /// The HDL-64E's range noise is under 2 cm; 3 cm leaves room for calibration and timing.
  float lidar_range_sigma_m = 0.03f;
  /// The inverse variance (m^-2) of a return's range, 1 / lidar_range_sigma_m^2: the weight of
  /// the free space that a LiDAR ray (or the open sky, or a ray beyond the range) shows.
  float lidarRangeWeight() const {
    const double sigma = lidar_range_sigma_m;
    return static_cast<float>(1.0 / (sigma * sigma));
  }
  float disagreement_k_sigma = 3.f;
  int lidar_range_window_px = 5;
  bool parallax_check = true;
  int parallax_max_rows = 16;

  // both methods, last: a fused disparity between the two surfaces of a depth edge takes the
  // nearest real return's (edge_support.h)
  bool edge_support = true;
  int edge_window_rows = 13;
  int edge_window_cols = 7;
  float edge_jump_px = 8.f;
  float edge_tolerance_px = 2.f;

  // after both: a LiDAR-backed wall goes on upward, row by row up each column, where the image
  // stays blank (facade_extension.h): near vertical surfaces only, at the anchors' inverse
  // depth; stereo that agrees on the way is averaged with it, stereo that disagrees replaced,
  // unless it sees a surface behind the wall (three pixels beyond 6 sigmas stop the column).
  bool facade_extension = true;
  // last: no depth in the open sky's clear pixels, clipped or blue, nor in front of the wall its
  // column's returns allow (clear_sky.h), found in the sky image (DepthImageFusion::setSkyImage;
  // msf_fuse's -color, or -left).
  bool clear_sky = true;
  // after the map took the frame: the small holes left take the nearest depth along their row or
  // column (hole_fill.h), at weight 0, so that the depth a user gets is dense where the sensors
  // left gaps and the map integrates none of them (Reconstructor::integrate, msf_fuse, msf_holdout).
  int hole_fill_px = 8;
  float facade_anchor_sigma_m = 0.2f;
  float facade_grey_tolerance = 8.f;
  float facade_max_texture = 4.f;
  float facade_sigma_per_m = 0.05f;
  float facade_max_normal_y = 0.3f;
  float facade_max_gap_m = 2.5f;

  template <class Keys>
  void keys(Keys& k) {
    k("method", method, kFusionMethods,
      "uncertainty (inverse variance in disparity, k-sigma test) or paper (eq. 6, dynamic weights)");
    k("paper_weights", paper_weights, kPaperWeights,
      "paper: eq. 6's w1, w2: relative (1, w_L / w_S) or as_written (w_S, w_L: w1 cancels)");
    k("paper_lidar_gain", paper_lidar_gain, atLeast(0), "paper: w_L on a real return");
    k("paper_lidar_distance_px", paper_lidar_distance_px, above(0),
      "paper: w_L halves this far from the nearest real return, px");
    k("paper_stereo_reference_depth_m", paper_stereo_reference_depth_m, above(0),
      "paper: w_S is the confidence up to this depth and falls as 1/z^2 beyond, m");
    k("paper_min_stereo_confidence", paper_min_stereo_confidence, above(0), "paper: floor of the confidence in w_S");
    k("stereo_sigma_min_px", stereo_sigma_min_px, above(0), "uncertainty: sigma of a stereo disparity of confidence 1, px");
    k("stereo_sigma_max_px", stereo_sigma_max_px, above(0),
      "... of confidence 0 (quadratic in 1 - confidence between), px");
    k("lidar_sigma_px", lidar_sigma_px, above(0), "uncertainty: sigma of the LiDAR's disparity at a real return, px");
    k("lidar_sigma_per_distance", lidar_sigma_per_distance, atLeast(0),
      "its growth per pixel of distance to the nearest real return");
    k("lidar_sigma_per_range", lidar_sigma_per_range, atLeast(0), "its growth per pixel of the edge cue");
    k("lidar_edge_cue", lidar_edge_cue, kLidarEdgeCues,
      "the edge cue: bend (the disparity's second difference, 0 on any plane) or range (max - min in the window)");
    k("lidar_range_sigma_m", lidar_range_sigma_m, above(0),
      "range noise of a LiDAR return, for the fused depth's weight 1 / sigma_z^2, m");
    k("disagreement_k_sigma", disagreement_k_sigma, above(0), "beyond k sigmas apart, the more certain sample wins alone");
    k("lidar_range_window_px", lidar_range_window_px, atLeast(1), "window of the edge cue, px (odd)");
    k("parallax_check", parallax_check, "stereo wins where the LiDAR (above the camera) saw past a foreground edge");
    k("parallax_max_rows", parallax_max_rows, atLeast(1), "rows below a pixel searched for that foreground");
    k("edge_support", edge_support,
      "a fused disparity between the two surfaces of a depth edge takes the nearest real return's");
    k("edge_window_rows", edge_window_rows, atLeast(1), "rows of the window of real returns (odd)");
    k("edge_window_cols", edge_window_cols, atLeast(1), "columns of that window (odd)");
    k("edge_jump_px", edge_jump_px, above(0), "an edge: the window's returns differ by more, px of disparity");
    k("edge_tolerance_px", edge_tolerance_px, atLeast(0), "a fused disparity this near a return is on its surface, px");
    k("facade_extension", facade_extension,
      "a LiDAR-backed wall goes on upward above the top ring where the image stays blank");
    k("clear_sky", clear_sky,
      "no depth in the open sky's clipped or blue pixels (SkyMask), nor in front of its column's returns: stereo "
      "smears crowns and poles there");
    k("hole_fill_px", hole_fill_px, atLeast(0),
      "a hole outside the open sky this near a depth along its row or column takes the nearest one, at "
      "weight 0 (not integrated); 0: off");
    k("facade_anchor_sigma_m", facade_anchor_sigma_m, above(0), "anchors: fused pixels known to within this, m");
    k("facade_grey_tolerance", facade_grey_tolerance, atLeast(0),
      "grey levels from the anchors' mean (5x5 box-filtered image)");
    k("facade_max_texture", facade_max_texture, atLeast(0),
      "blank: the grey's standard deviation over 5x5 pixels up to this, grey levels");
    k("facade_sigma_per_m", facade_sigma_per_m, atLeast(0), "the wall's sigma grows by this per metre above the last anchor");
    k("facade_max_normal_y", facade_max_normal_y, between(0, 1), "near vertical surfaces only: |n_y| of the unit normal");
    k("facade_max_gap_m", facade_max_gap_m, atLeast(0),
      "a window this high is crossed where stereo sees the wall, m (0: a window stops the column)");
  }
  /// Throws ConfigError naming the key of the first value out of range.
  void validate() const;
};

} // namespace msf
