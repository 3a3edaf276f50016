// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/range_image/depth_completion_filter.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/point_types.h>

namespace msf {

/// Paper step 2: compound interpolation of a sparse organized cloud (LidarProjector's
/// output), as a pcl::Filter. Rows and columns are slices; along a slice, a gap between
/// consecutive samples is bridged by the zero-slope cubic when it is at most short_gap_px
/// empty pixels, linearly up to max_gap_px, and not at all when longer or when the depth
/// jumps across it (an object edge). Depth is interpolated and x, y follow from the
/// pixel's ray. Row and column estimates are merged by the combine rule, then a normalized
/// Gaussian fills the small holes left. Samples are never changed; with PointXYZID each
/// point carries its distance in pixels to the nearest real return. Defaults and keys:
/// InterpolationConfig (YAML section `interpolation`).
///
///   msf::CompoundInterpolation<msf::PointXYZID> interpolation;
///   interpolation.setInputCloud(sparse);   // organized, e.g. from LidarProjector::project
///   interpolation.setCamera(msf::PinholeCamera::fromCalibration(calibration));
///   interpolation.filter(dense);
template <typename PointT>
class CompoundInterpolation : public DepthCompletionFilter<PointT> {
public:
  using Ptr = pcl::shared_ptr<CompoundInterpolation<PointT>>;
  using ConstPtr = pcl::shared_ptr<const CompoundInterpolation<PointT>>;

  CompoundInterpolation() { this->filter_name_ = "CompoundInterpolation"; }

  /// Throws ConfigError for an invalid config.
  void setConfig(const InterpolationConfig& config) {
    config.validate();
    config_ = config;
  }
  const InterpolationConfig& getConfig() const { return config_; }

  void setInterpolant(SliceInterpolant interpolant) { config_.slice.interpolant = interpolant; }
  SliceInterpolant getInterpolant() const { return config_.slice.interpolant; }
  void setShortGap(int pixels) { config_.slice.short_gap_px = pixels; }
  int getShortGap() const { return config_.slice.short_gap_px; }
  void setMaxGap(int pixels) { config_.slice.max_gap_px = pixels; }
  int getMaxGap() const { return config_.slice.max_gap_px; }
  /// Edge test: ends differing by more than abs_m + rel * (nearer depth).
  void setDepthJump(float abs_m, float rel) {
    config_.slice.jump_abs_m = abs_m;
    config_.slice.jump_rel = rel;
  }
  void setCombineRule(CombineRule rule) { config_.combine = rule; }
  CombineRule getCombineRule() const { return config_.combine; }
  void setGaussianFill(bool enabled) { config_.gaussian = enabled; }
  bool getGaussianFill() const { return config_.gaussian; }
  /// At most this many threads of OpenCV's pool (0: all of them); the result is the same for any number.
  void setNumberOfThreads(int threads) { config_.threads = threads; }
  int getNumberOfThreads() const { return config_.threads; }

protected:
  void completeDepth(const cv::Mat& sparse, cv::Mat& dense) override {
    interpolator_.setConfig(config_); // validates settings made one at a time
    interpolator_.interpolate(sparse, dense);
  }
  int threads() const override { return config_.threads; }

  InterpolationConfig config_;
  DepthInterpolator interpolator_;
};

} // namespace msf
