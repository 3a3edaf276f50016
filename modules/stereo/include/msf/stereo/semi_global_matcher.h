// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace msf {

/// Semi-global block matching of our own, vectorised with AVX2 (and AVX-512BW where the CPU
/// has it): the algorithm of OpenCV's StereoSGBM in MODE_SGBM_3WAY with the same parameters
/// and output, 2.2x (AVX2) to 3x (AVX-512) as fast per core as the Debian build of OpenCV 4.6
/// (whose SGBM is compiled for SSE2 only) on a KITTI frame at 128 disparities; with
/// diagonal_paths, the five paths of its MODE_SGBM; with p1_rise, a ground prior of its own
/// (Params::p1_rise). A portable kernel gives the same result on CPUs without AVX2.
///
/// Cost: Birchfield-Tomasi dissimilarity of the Sobel-x prefiltered images (clipped at
/// pre_filter_cap) plus a quarter of that of the raw images, summed over block_size^2;
/// paths left-to-right, right-to-left and top-to-bottom (and top-left to bottom-right and
/// top-right to bottom-left with diagonal_paths) with penalties p1, p2; winner with
/// the uniqueness ratio, parabolic sub-pixel, OpenCV's pseudo left-right check
/// (disp12_max_diff), cv::medianBlur's 3x3 median and the speckle filter (on row bands in
/// parallel, cv::filterSpeckles' result: parallel_post_filter.h). Rows run in 4 strips on
/// cv::parallel_for_ (each strip warms its top-to-bottom path up on rows above it, as
/// OpenCV does), so the result does not depend on the number of threads.
///
///   SemiGlobalMatcher matcher(params);
///   matcher.compute(left, right, disparity); // CV_16S, disparity x 16
///
/// Buffers are kept between calls, so after the first frame of a size nothing is allocated.
class SemiGlobalMatcher {
public:
  using Ptr = std::shared_ptr<SemiGlobalMatcher>;
  using ConstPtr = std::shared_ptr<const SemiGlobalMatcher>;

  /// OpenCV's StereoSGBM parameters, with its meaning for each.
  struct Params {
    int min_disparity = 0;
    int num_disparities = 128; ///< positive multiple of 16
    int block_size = 5;        ///< odd, 1..11
    int p1 = 200;              ///< > 0
    int p2 = 800;              ///< > p1
    /// The ground prior: the paths from above (top-to-bottom, and the diagonal ones) charge
    /// p1_rise rather than p1 for a disparity one pixel higher than at the pixel above. Down
    /// the image the ground, and what stands on it, comes nearer row by row (on KITTI a pixel
    /// of disparity every three rows); with p1 for such a rise, the paths from above hold the
    /// disparity of the rows above (SGM's fronto-parallel bias) and outvote the rows' paths.
    /// 0 or p1: OpenCV's paths; else 1..p2 - 1.
    int p1_rise = 0;
    int pre_filter_cap = 63;   ///< 1..63 (OpenCV uses max(cap, 15) | 1)
    int uniqueness_ratio = 10; ///< percent, 0..100; 0 = off
    int speckle_window_size = 100; ///< 0 = no speckle filter
    int speckle_range = 2;
    int disp12_max_diff = -1;  ///< pseudo left-right check in pixels; <= 0 means 1, as OpenCV 4.6
    /// Also the two diagonal paths from above (OpenCV's MODE_SGBM, five paths in all): a
    /// blank wall between periodic windows, which the rows alone match at a window's pitch,
    /// takes the disparity of the textured pixels above and beside it. ~1.25x the time.
    bool diagonal_paths = false;
    /// Guidance (compute() with a hint image): at a pixel with a hint, each disparity d's
    /// block cost grows by min(guidance_gain * |d - hint|, guidance_max_penalty) before the
    /// paths, which carry the hint to the pixels around. 0..kMaxGuidanceGain per pixel of
    /// disparity and 0..kMaxGuidancePenalty (block costs are 25 x 0..189 at block 5); either
    /// 0: hints are ignored.
    int guidance_gain = 0;
    int guidance_max_penalty = 0;
  };

  /// Bounds of Params::guidance_gain and guidance_max_penalty (16-bit arithmetic).
  static constexpr int kMaxGuidanceGain = 1000;
  static constexpr int kMaxGuidancePenalty = 4000;

  SemiGlobalMatcher() = default;
  explicit SemiGlobalMatcher(const Params& params) { setParams(params); }

  /// True when compute() runs the AVX2 kernel (or the AVX-512 one): this build has it, the
  /// CPU runs it and it is not disabled. Else the portable kernel runs, with the same result.
  static bool usesAvx2();
  /// Disables (false) or re-enables the AVX2 and AVX-512 kernels process-wide, so that tests
  /// and benchmarks can run the portable kernel (and SgbmStereo its OpenCV fallback) on a
  /// machine with AVX2.
  static void setAvx2Enabled(bool enabled);
  /// True when compute() runs the AVX-512BW kernel (32 disparities per instruction, the
  /// same result as the AVX2 one, faster) for a number of
  /// disparities that is a multiple of 32: the CPU has it and it is not disabled.
  static bool usesAvx512();
  /// Disables (false) or re-enables the AVX-512 kernel process-wide (AVX2 runs instead).
  static void setAvx512Enabled(bool enabled);

  /// Widest image it matches (4032 px).
  static int maxWidth();

  /// Throws ConfigError naming the parameter out of range.
  void setParams(const Params& params);
  const Params& getParams() const { return params_; }

  /// Disparity of the left image (CV_16S, disparity x 16, (min_disparity - 1) x 16 where
  /// none; the first min_disparity + num_disparities columns have none, as OpenCV's).
  /// Throws InvalidInputError for images that are empty, not 8-bit grey, of different sizes
  /// or wider than maxWidth().
  void compute(const cv::Mat& left, const cv::Mat& right, cv::Mat& disparity);
  /// The same, guided by `guidance` (Poggi et al., "Guided Stereo Matching", CVPR 2019):
  /// CV_16SC1 of the images' size, disparity x 16 of the left view, <= 0 where there is no
  /// hint (such as projected LiDAR returns). Pixels without a hint have their own costs, but
  /// the paths bring the hints' costs to them. Empty `guidance`: exactly compute() without
  /// it. Throws InvalidInputError for a guidance of another type or size, and when
  /// min_disparity + num_disparities exceeds maxGuidedDisparity().
  void compute(const cv::Mat& left, const cv::Mat& right, cv::Mat& disparity, const cv::Mat& guidance);

  /// Largest |disparity| that guidance handles (its lanes are 16-bit, in 1/16 px).
  static int maxGuidedDisparity();

private:
  Params params_;
  std::vector<std::vector<std::uint8_t>> workspaces_; // one per strip
  cv::Mat raw_, speckle_buffer_;
};

} // namespace msf
