// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_config.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>

#include <memory>

namespace cv {
class StereoSGBM;
}

namespace msf {

/// Dense stereo depth (paper step 3): semi-global block matching on a rectified grey pair
/// (config.engine: our SemiGlobalMatcher, or OpenCV's StereoSGBM; config.mode guided by the
/// LiDAR, config.unguided_mode without), to a disparity image, a per-pixel confidence
/// (stereo_confidence.h) and an organized cloud in the rectified frame of camera 0 with
/// z = f B / d, coloured from the colour camera.
///
///   msf::SgbmStereo stereo;
///   stereo.setCalibration(calibration);
///   stereo.setInputImages(left, right);          // KITTI image_0, image_1
///   stereo.setInputColor(color);                  // image_2, optional
///   stereo.setDepthPrior(lidar_depth);            // optional: narrows the search range
///   stereo.setGuidance(lidar_sparse);             // optional, with config.guidance lidar
///   pcl::PointCloud<msf::PointXYZRGBConfidence> cloud;
///   stereo.compute(cloud);                        // width x height of the images
///
/// Not a pcl::Filter: its input is a pair of images, not a cloud (as pcl::stereo). The
/// matcher is kept between frames, so its buffers are reused.
class SgbmStereo {
public:
  using Ptr = std::shared_ptr<SgbmStereo>;
  using ConstPtr = std::shared_ptr<const SgbmStereo>;

  using Config = SgbmConfig;

  SgbmStereo() = default;
  explicit SgbmStereo(const Config& config) { setConfig(config); }

  /// Throws ConfigError naming the key of a value out of range.
  void setConfig(const Config& config);
  const Config& getConfig() const { return config_; }

  /// Needed by compute() (f, B, the colour camera) and, when it knows the image size, used
  /// to check the images.
  void setCalibration(const Calibration& calibration);
  const Calibration& getCalibration() const { return calibration_; }

  /// Rectified left (camera 0) and right (camera 1) images, 8-bit grey or BGR.
  void setInputImages(const cv::Mat& left, const cv::Mat& right);
  /// Image of the colour camera (config.color_camera), BGR; empty: colour from the left image.
  void setInputColor(const cv::Mat& color) { color_ = color; }
  /// Depth prior (CV_32F metres, 0 = none), such as the interpolated LiDAR depth; with
  /// config.prior_search_range it narrows the disparity search. Empty: no prior.
  void setDepthPrior(const cv::Mat& depth) { prior_ = depth; }
  /// Sparse depth that guides the matching when config.guidance is lidar (CV_32F metres,
  /// 0 = none): the projected LiDAR returns (LidarProjector::projectToImage), never an
  /// interpolation, whose errors the paths would spread. Each return's disparity f B / z
  /// becomes a hint of SemiGlobalMatcher::compute. Empty, or guidance none: unguided.
  void setGuidance(const cv::Mat& sparse_depth) { guidance_ = sparse_depth; }

  /// Matches the pair: fills getDisparity() and getConfidence().
  /// Throws InvalidInputError naming the image at fault (missing, empty, sizes differ,
  /// size differs from the calibration, not 8-bit).
  void computeDisparity();

  /// computeDisparity(), then the organized cloud: NaN where there is no disparity, rgb
  /// from the colour camera where PointT has colour, `confidence` where PointT has it.
  /// Instantiated for pcl::PointXYZ, pcl::PointXYZRGB, pcl::PointXYZRGBA and
  /// msf::PointXYZRGBConfidence. Throws CalibrationError when no calibration was set.
  template <typename PointT>
  void compute(pcl::PointCloud<PointT>& output);

  /// Disparity in pixels (CV_32F, 0 = none) of the last computeDisparity().
  const cv::Mat& getDisparity() const { return disparity_; }
  /// Confidence in [0, 1] (CV_32F, 0 = no disparity) of the last computeDisparity().
  const cv::Mat& getConfidence() const { return confidence_; }
  /// Depth in metres (CV_32F, 0 = none) of the last computeDisparity().
  cv::Mat getDepth() const;
  /// Number of disparities searched by the last computeDisparity() (narrowed by the prior).
  int getSearchedDisparities() const { return searched_disparities_; }
  /// The engine that ran the last computeDisparity(): "native" or "opencv" (the fallback
  /// where native was asked for but the mode is hh or hh4, or sgbm or sgbm_3way on a CPU
  /// without AVX2, or the images are wider than SemiGlobalMatcher::maxWidth()).
  const std::string& getEngineUsed() const { return engine_used_; }

private:
  cv::Mat match(const cv::Mat& left, const cv::Mat& right, int num_disparities, const cv::Mat& hints);
  void runMatcher(const cv::Mat& left, const cv::Mat& right, int num_disparities, const cv::Mat& hints,
                  cv::Mat& fixed);
  bool nativeRuns(int width, const std::string& mode) const;
  void checkInputs() const;

  Config config_;
  Calibration calibration_;
  bool has_calibration_{false};
  cv::Mat left_, right_, color_, prior_, guidance_;
  cv::Mat disparity_, confidence_;
  int searched_disparities_{0};
  std::string engine_used_;
  cv::Ptr<cv::StereoSGBM> matcher_;
  SemiGlobalMatcher native_;
};

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/stereo/impl/sgbm_stereo.hpp>
#endif
