// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/stereo_confidence.h>

#include <string>

namespace msf {

/// Every parameter of SgbmStereo: section `stereo` of a config file. The defaults: OpenCV's
/// 5-path SGBM (mode sgbm) where the LiDAR's returns guide it, the 3-way paths with the ground
/// prior (unguided_mode ground_3way) where nothing does, on 128 disparities with 5x5 blocks,
/// narrowed by a LiDAR depth prior when one is given (the paper's configuration is OpenCV's
/// 3-way mode, unguided).
struct SgbmConfig {
  static constexpr const char* kSection = "stereo";
  static constexpr const char* kAbout = "SgbmStereo (paper step 3): semi-global matching of the grey pair";
  /// native: our AVX2 / AVX-512 matcher (SemiGlobalMatcher), OpenCV's algorithm and parameters,
  /// and ground_3way; for hh and hh4, and for sgbm and sgbm_3way on a CPU without AVX2, it falls
  /// back to OpenCV with a one-time note.
  std::string engine = "native";
  /// Guided by the LiDAR, five paths beat three on KITTI and on the synthetic streets
  /// (docs/results.md, "Depth at held-out LiDAR rings").
  std::string mode = "sgbm";
  /// Unguided, ground_3way beats OpenCV's 3-way, where five paths lose to it (docs/results.md,
  /// "The unguided matcher").
  std::string unguided_mode = "ground_3way";
  int min_disparity_px = 0;
  int num_disparities_px = 128;
  int block_size_px = 5;
  int p1 = 0;
  int p2 = 0;
  int p1_rise = 0;
  int pre_filter_cap = 63;
  int uniqueness_ratio_pct = 10;
  int speckle_window_size_px = 100;
  int speckle_range_px = 2;
  /// OpenCV's pseudo left-right check against the right-view winners gathered from the left
  /// matches; OpenCV 4.6 never turns it off (<= 0 means 1 px), and neither does native.
  int disp12_max_diff_px = -1;
  bool left_right_check = false;
  float left_right_max_diff_px = 1.f;
  /// The pair is padded on the left by replicating its first column, and a disparity that
  /// points outside the right image (d > u) is dropped. Stereo alone gains coverage; the
  /// fusion, where the LiDAR covers that band, does not, hence off.
  bool match_left_border = false;
  bool prior_search_range = true;
  int prior_margin_px = 8;
  /// Guided matching (Poggi et al., CVPR 2019): the projected LiDAR returns given to
  /// SgbmStereo::setGuidance raise the cost of disparities away from theirs at their pixels
  /// (and at the rows bridged between them), by min(guidance_gain * |d - d_lidar|,
  /// guidance_max_penalty), and the paths carry that on to the pixels around. The native
  /// engine's (where OpenCV runs instead, a one-time note says it is ignored).
  std::string guidance = "lidar";
  int guidance_gain = 400;
  int guidance_max_penalty = 1500;
  /// Rows between two returns of a column bridged by hints linear between theirs
  /// (guidanceHints), when their disparities differ by at most guidance_bridge_agreement of the larger.
  int guidance_bridge_rows = 48;
  float guidance_bridge_agreement = 0.25f;
  float max_depth_m = 0.f;
  int color_camera = 2;
  StereoConfidenceConfig confidence;

  static constexpr const char* kModes[] = {"sgbm", "sgbm_3way", "ground_3way", "hh", "hh4"};

  template <class Keys>
  void keys(Keys& k) {
    k("engine", engine, {"native", "opencv"},
      "the matcher: ours (AVX2, OpenCV's algorithm, 2-3x faster) or OpenCV's cv::StereoSGBM");
    k("mode", mode, kModes,
      "SGBM's paths where the LiDAR's returns guide the matching (guidance lidar and returns given): 5 (sgbm: "
      "left, right, top and the diagonals from above), 3, 3 with the ground prior, 8 (hh) or 4 (hh4)");
    k("unguided_mode", unguided_mode, kModes,
      "the paths where nothing guides it (msf_stereo alone, guidance none); ground_3way: OpenCV's 3-way paths, the "
      "top-to-bottom one with the ground prior (p1_rise; native engine only, engine opencv runs sgbm_3way)");
    k("min_disparity_px", min_disparity_px, anyNumber(), "smallest disparity searched, px");
    k("num_disparities_px", num_disparities_px, atLeast(16),
      "disparities searched without a LiDAR prior, px (a multiple of 16)");
    k("block_size_px", block_size_px, between(1, 11), "matched block's side, px (odd)");
    k("p1", p1, atLeast(0), "smoothness penalty of a +-1 px step (0: 8 * block_size_px^2)");
    k("p2", p2, atLeast(0), "penalty of a larger step, above p1 (0: 32 * block_size_px^2)");
    k("p1_rise", p1_rise, atLeast(0),
      "ground_3way's penalty of a disparity one pixel higher than the row above's along the top-to-bottom path, "
      "below p2 (0: 3 * block_size_px^2)");
    k("pre_filter_cap", pre_filter_cap, between(1, 63), "clip of the prefiltered image's gradient");
    k("uniqueness_ratio_pct", uniqueness_ratio_pct, between(0, 100),
      "the best cost must beat the second best by this margin, %");
    k("speckle_window_size_px", speckle_window_size_px, atLeast(0),
      "connected regions of disparity smaller than this are removed, px (0: no speckle filter)");
    k("speckle_range_px", speckle_range_px, atLeast(0), "largest disparity step within one region, px");
    k("disp12_max_diff_px", disp12_max_diff_px, anyNumber(),
      "OpenCV's pseudo left-right check, px (<= 0: 1 px; it is never off)");
    k("left_right_check", left_right_check, "check each match against a match of the right view (2x the time)");
    k("left_right_max_diff_px", left_right_max_diff_px, atLeast(0), "largest disagreement of that check, px");
    k("match_left_border", match_left_border,
      "match the first min_disparity + num_disparities columns too, which OpenCV leaves empty");
    k("prior_search_range", prior_search_range,
      "narrow the search to a LiDAR depth prior's disparities when one is given");
    k("prior_margin_px", prior_margin_px, atLeast(0), "disparities searched beyond the prior's largest, px");
    k("guidance", guidance, {"lidar", "none"},
      "raise the cost of disparities away from the LiDAR returns' at their pixels (Poggi et al. 2019), or not");
    k("guidance_gain", guidance_gain, between(0, SemiGlobalMatcher::kMaxGuidanceGain), "guidance cost per pixel of disparity from the return's");
    k("guidance_max_penalty", guidance_max_penalty, between(0, SemiGlobalMatcher::kMaxGuidancePenalty),
      "guidance cost's cap (P2 is 800 at block 5)");
    k("guidance_bridge_rows", guidance_bridge_rows, atLeast(0),
      "rows between two returns of a column guided by a bridge between them (0: the returns only)");
    k("guidance_bridge_agreement", guidance_bridge_agreement, atLeast(0),
      "a bridge's ends differ by at most this share of the larger disparity");
    k("max_depth_m", max_depth_m, atLeast(0), "depths beyond this are dropped, m (0: none)");
    k("color_camera", color_camera, between(0, 3), "camera whose image colours the cloud (KITTI's image_2: 2)");
    confidence.keys(k);
  }

  /// P1 and P2 with the 0 defaults resolved for single-channel images.
  int resolvedP1() const { return p1 > 0 ? p1 : 8 * block_size_px * block_size_px; }
  int resolvedP2() const { return p2 > 0 ? p2 : 32 * block_size_px * block_size_px; }
  int resolvedP1Rise() const { return p1_rise > 0 ? p1_rise : 3 * block_size_px * block_size_px; }
  /// The mode that runs: `mode` when guided, else `unguided_mode`.
  const std::string& modeFor(bool guided) const { return guided ? mode : unguided_mode; }
  /// OpenCV's cv::StereoSGBM mode constant of modeFor(guided) (ground_3way: its 3-way).
  int opencvMode(bool guided) const;
  /// True when engine is native (whether or not the CPU can run it).
  bool nativeEngine() const { return engine == "native"; }
  /// True when guidance is lidar (false for none).
  bool lidarGuidance() const { return guidance == "lidar"; }

  /// Throws ConfigError naming the key of the first value out of range.
  void validate() const;
};

} // namespace msf
