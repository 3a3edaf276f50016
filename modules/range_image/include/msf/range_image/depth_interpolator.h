// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/common/limits.h>
#include <msf/common/parallel.h>
#include <msf/range_image/slice_interpolation.h>

#include <opencv2/core/mat.hpp>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// How the row and the column estimate of a pixel are merged when both exist. The shorter gap
/// wins on KITTI (docs/results.md) because its ends are nearer the pixel: between two scan
/// lines that is the column, along one the row.
enum class CombineRule {
  Average,     ///< mean of the two
  ShorterGap,  ///< the estimate bridged over the shorter gap (the more local one); mean on a tie
  GapWeighted, ///< weights 1 / (gap + 1)
  Nearest      ///< the smaller depth: foreground wins
};
inline constexpr Choice<CombineRule> kCombineRules[] = {{"shorter_gap", CombineRule::ShorterGap},
                                                       {"average", CombineRule::Average},
                                                       {"gap_weighted", CombineRule::GapWeighted},
                                                       {"nearest", CombineRule::Nearest}};
const char* toString(CombineRule rule);

/// Section `interpolation` of a config file (paper step 2, compound interpolation).
struct InterpolationConfig {
  static constexpr const char* kSection = "interpolation";
  static constexpr const char* kAbout =
      "CompoundInterpolation (paper step 2): rows and columns of the sparse LiDAR depth bridged, then one "
      "Gaussian pass over the holes";
  SliceParams slice;
  CombineRule combine = CombineRule::ShorterGap;
  /// Row estimates bridged over at most this many pixels join the samples that column
  /// slices see (0: columns see samples only). A scan line is dense along a row but its
  /// samples share azimuths, so without this, whole columns have no sample at all.
  int column_seed_gap_px = 3;
  bool gaussian = true;
  int gaussian_size_px = 9;
  float gaussian_sigma_px = 2.0f;
  float gaussian_min_weight = 0.1f;
  bool gaussian_smooth_valid = false;
  int threads = 0;

  template <class Keys>
  void keys(Keys& k) {
    slice.keys(k);
    k("column_seed_gap_px", column_seed_gap_px, atLeast(0),
      "row estimates over gaps of at most this many pixels seed the column slices (0: samples only), px");
    k("combine", combine, kCombineRules,
      "a pixel with a row and a column estimate takes: the one over the shorter gap, their average, their "
      "mean weighted by 1 / (gap + 1), or the nearer");
    k("gaussian", gaussian, "fill the holes left by the slices with a normalized Gaussian");
    k("gaussian_size_px", gaussian_size_px, between(1, 31), "the Gaussian's width, px (odd)");
    k("gaussian_sigma_px", gaussian_sigma_px, above(0), "the Gaussian's sigma, px");
    k("gaussian_min_weight", gaussian_min_weight, Range{0, 1, true, false},
      "share of the kernel's mass that must hold estimates for a hole to be filled");
    k("gaussian_smooth_valid", gaussian_smooth_valid, "also smooth the interpolated pixels (never the real returns)");
    k("threads", threads, between(0, limits::kMaxThreads), "at most this many threads of OpenCV's pool (0: all)");
  }
  /// Throws ConfigError naming the first key out of range.
  void validate() const;
};

/// The image-level core of CompoundInterpolation: a sparse depth image (CV_32FC1, 0 or
/// NaN = no sample) to an interpolated one (CV_32FC1, 0 = no estimate). Rows are slices
/// first; then columns, whose seeds are the samples and the short row bridges; a pixel
/// with both estimates takes `combine`'s; then one normalized Gaussian pass fills the
/// small holes that remain. Samples are never changed. The object
/// keeps its work buffers between calls (one frame after another); it is not meant to be
/// shared between threads, but each call is parallel inside and gives the same result
/// for any number of threads.
class DepthInterpolator {
public:
  using Ptr = std::shared_ptr<DepthInterpolator>;
  using ConstPtr = std::shared_ptr<const DepthInterpolator>;

  explicit DepthInterpolator(const InterpolationConfig& config = {});
  /// Throws ConfigError for an invalid config.
  void setConfig(const InterpolationConfig& config);
  const InterpolationConfig& config() const { return config_; }

  /// Throws InvalidInputError when `depth` is not CV_32FC1 or empty. `out` may not alias `depth`.
  void interpolate(const cv::Mat& depth, cv::Mat& out);

private:
  void prepareHoleFill(int width);
  /// The normalized Gaussian pass over the holes of `out`, in `stripes` pieces (cv::parallel_for_).
  void fillHoles(const cv::Mat& depth, cv::Mat& out, double stripes);

  InterpolationConfig config_;
  cv::Mat row_gap_, values_, weights_, targets_;
  std::vector<int> last_;     ///< column pass: row of the previous seed of each column
  std::vector<float> z_last_; ///< and its depth
  std::vector<char> row_has_; ///< rows with a sample
  std::vector<float> kernel_; ///< normalized 1-D Gaussian
};

} // namespace msf
