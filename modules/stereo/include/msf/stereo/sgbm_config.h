// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/stereo/stereo_confidence.h>

#include <opencv2/core/persistence.hpp>

#include <iosfwd>
#include <string>

namespace msf {

/// Every parameter of SgbmStereo, read from the `stereo` section of a config file.
/// Defaults: OpenCV's 5-path SGBM (mode sgbm) where the LiDAR's returns guide it, the 3-way
/// paths with the ground prior (unguided_mode ground_3way) where nothing does, on 128
/// disparities with 5x5 blocks, narrowed by a LiDAR depth prior when one is given (OpenCV's
/// 3-way mode is the baseline docs/results.md quotes and the paper's configuration).
struct SgbmConfig {
  /// native: our AVX2 / AVX-512 matcher (SemiGlobalMatcher), the same algorithm and
  /// parameters as OpenCV's 3-way SGBM (and its 5-path sgbm), 2-3x faster per core, and
  /// ground_3way; for hh and hh4, and for sgbm and sgbm_3way on a CPU without AVX2, it falls
  /// back to OpenCV with a one-time note. opencv: cv::StereoSGBM.
  std::string engine = "native";
  /// The paths where the LiDAR's returns guide the matching (guidance lidar and returns given:
  /// msf_reconstruct, msf_stereo -prior): sgbm (5 paths) | sgbm_3way | ground_3way | hh (8
  /// paths) | hh4. Guided, five paths beat three on KITTI (odometry 04 and raw 0009 fused D1)
  /// and on the streets' meshes (docs/results.md, "Five paths").
  std::string mode = "sgbm";
  /// The paths where nothing guides it (msf_stereo alone, guidance none), the same names.
  /// ground_3way: OpenCV's 3-way paths, the top-to-bottom one with the ground prior (p1_rise;
  /// native engine only, engine opencv runs sgbm_3way): unguided it beats OpenCV's 3-way,
  /// where five paths lose to it (docs/results.md, "The unguided matcher").
  std::string unguided_mode = "ground_3way";
  int min_disparity_px = 0;
  int num_disparities_px = 128;    ///< positive multiple of 16; the search range without a prior
  int block_size_px = 5;           ///< odd, 1..11
  int p1 = 0;                      ///< smoothness penalty for +-1 px steps; 0: 8 * block^2
  int p2 = 0;                      ///< penalty for larger steps, > p1; 0: 32 * block^2
  /// ground_3way's penalty for a disparity one pixel higher than the row above's along the
  /// top-to-bottom path (SemiGlobalMatcher::Params::p1_rise), < p2; 0: 3 * block^2.
  int p1_rise = 0;
  int pre_filter_cap = 63;
  int uniqueness_ratio_pct = 10;
  int speckle_window_size_px = 100; ///< 0 disables the speckle filter
  int speckle_range_px = 2;
  /// OpenCV's pseudo left-right check against the right-view winners gathered from the
  /// left matches; OpenCV 4.6 never turns it off (<= 0 means 1 px), and neither does native.
  int disp12_max_diff_px = -1;
  bool left_right_check = false;   ///< explicit check against a right-view match (2x the time)
  float left_right_max_diff_px = 1.f;
  /// Match the first min_disparity + num_disparities columns too (OpenCV leaves them empty):
  /// the pair is padded on the left by replicating its first column, and a disparity that
  /// points outside the right image (d > u) is dropped. Stereo alone gains 2-3 % coverage on
  /// KITTI for about a quarter more time; the fusion, where the LiDAR covers that band,
  /// gains nothing measurable, hence off.
  bool match_left_border = false;
  bool prior_search_range = true;  ///< narrow num_disparities to a depth prior when given
  int prior_margin_px = 8;         ///< disparities beyond the prior's largest
  /// Guided matching (Poggi et al., CVPR 2019): lidar: the projected LiDAR returns given to
  /// SgbmStereo::setGuidance raise the cost of disparities away from theirs at their pixels
  /// (and at the rows bridged between them), by min(guidance_gain * |d - d_lidar|,
  /// guidance_max_penalty), and the paths carry that on to the pixels around; none: ignored.
  /// The native engine's (where OpenCV runs instead, a one-time note says it is ignored).
  /// Defaults measured on odometry 04 (protocol 2): fused D1 3.29 -> 3.11 %, MAE 1.088 -> 1.042 m.
  std::string guidance = "lidar";
  int guidance_gain = 400;         ///< cost per pixel of disparity, 0..1000
  int guidance_max_penalty = 1500; ///< 0..4000 (P2 is 800 at block 5)
  /// Rows between two returns of a column bridged by hints linear between theirs (guidanceHints),
  /// when their disparities differ by at most guidance_bridge_agreement of the larger; 0: none.
  int guidance_bridge_rows = 48;
  float guidance_bridge_agreement = 0.25f;
  float max_depth_m = 0.f;         ///< drop depths beyond this; 0 keeps all
  int color_camera = 2;            ///< camera whose image colours the cloud
  StereoConfidenceConfig confidence;

  /// P1 and P2 with the 0 defaults resolved for single-channel images.
  int resolvedP1() const { return p1 > 0 ? p1 : 8 * block_size_px * block_size_px; }
  int resolvedP2() const { return p2 > 0 ? p2 : 32 * block_size_px * block_size_px; }
  int resolvedP1Rise() const { return p1_rise > 0 ? p1_rise : 3 * block_size_px * block_size_px; }
  /// The mode that runs: `mode` when guided, else `unguided_mode`.
  const std::string& modeFor(bool guided) const { return guided ? mode : unguided_mode; }
  /// OpenCV's cv::StereoSGBM mode constant of modeFor(guided) (ground_3way: its 3-way).
  int opencvMode(bool guided) const;
  /// True when engine is native (whether or not the CPU can run it).
  bool nativeEngine() const;
  /// True when guidance is lidar (false for none).
  bool lidarGuidance() const;

  /// Overrides the keys present in `node` (the `stereo` section), then validates.
  void read(const cv::FileNode& node);
  /// Throws ConfigError naming the key of the first value out of range.
  void validate() const;
  void print(std::ostream& out) const;
};

} // namespace msf
