// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/facade_extension.h>
#include <msf/fusion/hole_fill.h>
#include <msf/range_image/real_returns.h>

#include <opencv2/core/utility.hpp>

#include <string>

namespace msf {

namespace {
void check(const cv::Mat& image, const char* name, const cv::Size& size, bool optional) {
  if (optional && image.empty())
    return;
  if (image.type() != CV_32FC1)
    throw InvalidInputError(std::string("depth fusion: ") + name + " must be CV_32FC1");
  if (image.size() != size)
    throw InvalidInputError(std::string("depth fusion: ") + name + " is " + std::to_string(image.cols) + "x" +
                            std::to_string(image.rows) + " but the LiDAR depth is " + std::to_string(size.width) +
                            "x" + std::to_string(size.height));
}
} // namespace

void DepthImageFusion::setConfig(const DepthFusionConfig& config) {
  config.validate();
  config_ = config;
  parallax_ = lidarParallax(calibration_, config_);
}

void DepthImageFusion::setCalibration(const Calibration& calibration) {
  if (!(calibration.focalBaseline() > 0.0))
    throw CalibrationError("calibration '" + calibration.source +
                           "': the grey pair has no baseline (P1 must hold -f B in its last column)");
  calibration_ = calibration;
  focal_baseline_ = calibration.focalBaseline();
  parallax_ = lidarParallax(calibration, config_);
}

void DepthImageFusion::fuse(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
                            const cv::Mat& stereo_confidence, cv::Mat& fused_depth, cv::Mat* fused_weight,
                            cv::Mat* free_space_weight) {
  if (lidar_depth.empty())
    throw InvalidInputError("depth fusion: the LiDAR depth image is empty");
  const cv::Size size = lidar_depth.size();
  check(lidar_depth, "the LiDAR depth image", size, false);
  check(lidar_distance, "the LiDAR distance image", size, true);
  check(stereo_depth, "the stereo depth image", size, false);
  check(stereo_confidence, "the stereo confidence image", size, true);
  if (!(focal_baseline_ > 0.0))
    throw CalibrationError("depth fusion: no calibration set (setCalibration)");

  const bool uncertainty = config_.method == FusionMethod::Uncertainty;
  const auto filled = [&](const cv::Mat& image, cv::Mat& buffer, float value) -> const cv::Mat& {
    if (!image.empty())
      return image;
    if (buffer.size() != size || buffer.type() != CV_32FC1 || buffer.at<float>(0, 0) != value)
      buffer = cv::Mat(size, CV_32FC1, cv::Scalar(value));
    return buffer;
  };
  const cv::Mat& distance = filled(lidar_distance, zeros_, 0.f);
  const cv::Mat& confidence = filled(stereo_confidence, ones_, 1.f);
  // The row kernel treats every depth that is not > 0 (0, negative, NaN) as none.
  const cv::Mat& lidar = lidar_depth;
  const cv::Mat& stereo = stereo_depth;
  if (uncertainty)
    lidarEdgeCue(lidar, focal_baseline_, config_, edge_);
  else { // the paper's method reads no edge cue
    edge_.create(size, CV_32FC1);
    edge_.setTo(0);
  }
  fused_depth.create(size, CV_32FC1);
  cv::Mat& weight = fused_weight ? *fused_weight : weight_;
  weight.create(size, CV_32FC1);
  cv::Mat& free_weight = free_space_weight ? *free_space_weight : free_weight_;
  free_weight.create(size, CV_32FC1);
  const float fB = static_cast<float>(focal_baseline_);
  parallelFor(cv::Range(0, size.height), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v)
      fuseRow(config_, fB, parallax_, lidar, v, distance.ptr<float>(v), edge_.ptr<float>(v), stereo.ptr<float>(v),
              confidence.ptr<float>(v), fused_depth.ptr<float>(v), weight.ptr<float>(v),
              free_weight.ptr<float>(v));
  });
  if (config_.edge_support)
    supportAtDepthEdges(lidar, distance, fB, config_, fused_depth, edge_buffers_);
  if (config_.facade_extension && !left_.empty())
    extendFacades(left_, calibration_, config_, fused_depth, weight, free_weight);
  open_sky_.release();
  clear_sky_.release();
  returns_.release();
  if (sky_image_.empty())
    return;
  if (sky_image_.size() != size)
    throw InvalidInputError("depth fusion: the sky image is " + std::to_string(sky_image_.cols) + "x" +
                            std::to_string(sky_image_.rows) + ", the depth images " + std::to_string(size.width) +
                            "x" + std::to_string(size.height));
  returns_ = realReturns(lidar, distance);
  if (config_.clear_sky)
    open_sky_ = withholdClearSky(sky_, sky_image_, left_, returns_, fused_depth, weight, free_weight, &clear_sky_);
}

cv::Mat DepthImageFusion::openSkyMask() const {
  if (returns_.empty())
    return {};
  return open_sky_.empty() ? sky_.compute(sky_image_, returns_) : open_sky_;
}

void DepthImageFusion::findOpenSky(cv::Mat& sky, cv::Mat& sky_depth) const {
  sky = openSkyMask();
  if (sky.empty()) {
    sky_depth.release();
    return;
  }
  sky_depth = skyDepthImage(sky, sky_.topReturnDepth(returns_), clear_sky_);
}

void DepthImageFusion::fillSmallHoles(cv::Mat& fused_depth, cv::Mat* fused_weight, cv::Mat* free_space_weight) const {
  if (config_.hole_fill_px <= 0)
    return;
  cv::Mat no_weight;
  msf::fillSmallHoles(fused_depth, fused_weight ? *fused_weight : no_weight,
                      free_space_weight ? *free_space_weight : no_weight, openSkyMask(), config_.hole_fill_px);
}

void fuseDepthImages(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
                     const cv::Mat& stereo_confidence, const Calibration& calibration,
                     const DepthFusionConfig& config, cv::Mat& fused_depth, cv::Mat* fused_weight) {
  DepthImageFusion fusion(config);
  fusion.setCalibration(calibration);
  fusion.fuse(lidar_depth, lidar_distance, stereo_depth, stereo_confidence, fused_depth, fused_weight);
}

} // namespace msf
