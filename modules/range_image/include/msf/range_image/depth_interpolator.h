// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <iosfwd>
#include <msf/common/parallel.h>
#include <msf/range_image/slice_interpolation.h>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/persistence.hpp>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// How the row and the column estimate of a pixel are merged when both exist. Measured
/// under protocol 2 (odometry 04, frames 0-9, D1 with missing = bad): shorter_gap 4.26 %,
/// nearest 4.40 %, gap_weighted 4.44 %, average 4.64 %. The shorter gap wins because its
/// ends are nearer the pixel: between two scan lines that is the column, along one the row.
enum class CombineRule {
  Average,     ///< mean of the two
  ShorterGap,  ///< the estimate bridged over the shorter gap (the more local one); mean on a tie
  GapWeighted, ///< weights 1 / (gap + 1)
  Nearest      ///< the smaller depth: foreground wins
};
/// "average", "shorter_gap", "gap_weighted", "nearest"; throws ConfigError otherwise.
CombineRule parseCombineRule(const std::string& name);
const char* toString(CombineRule rule);

/// Section `interpolation` of the YAML config (paper step 2, compound interpolation).
struct InterpolationConfig {
  SliceParams slice;                        ///< keys method, short_gap_px, max_gap_px, edge_test, jump_abs_m,
                                            ///< jump_rel, jump_inv_per_m, cubic_alpha, cubic_beta,
                                            ///< inverse_depth
  CombineRule combine = CombineRule::ShorterGap;
  /// Row estimates bridged over at most this many pixels join the samples that column
  /// slices see (0: columns see samples only). A scan line is dense along a row but its
  /// samples share azimuths, so without this, whole columns have no sample at all.
  int column_seed_gap_px = 3;
  bool gaussian = true;                     ///< fill the holes left by the slices
  int gaussian_size_px = 9;                 ///< odd kernel width
  float gaussian_sigma_px = 2.0f;
  float gaussian_min_weight = 0.1f;         ///< share of the kernel's mass that must hold estimates
  bool gaussian_smooth_valid = false;       ///< also smooth interpolated pixels (real returns never)
  int threads = 0;                          ///< at most this many threads of OpenCV's pool, 0 = all of them

  /// The section as YAML, every key (configValue).
  void print(std::ostream& out) const;
  void read(const cv::FileNode& node);
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
