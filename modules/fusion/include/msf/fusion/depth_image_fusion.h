// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/edge_support.h>
#include <msf/fusion/fusion_config.h>
#include <msf/fusion/fusion_model.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/calibration.h>

#include <opencv2/core/mat.hpp>

#include <memory>
#include <vector>

namespace msf {

/// DepthFusion on images, for pipelines that keep depth images between stages (the
/// evaluation, the TSDF integrator): the same per-pixel model (fusion_model.h) without
/// clouds, so a frame moves a quarter of the memory. Keeps its work buffers between frames;
/// one object per thread.
///
///   msf::DepthImageFusion fusion(config);
///   fusion.setCalibration(calibration);
///   fusion.fuse(lidar_depth, lidar_distance, stereo_depth, stereo_confidence, fused_depth);
class DepthImageFusion {
public:
  using Ptr = std::shared_ptr<DepthImageFusion>;
  using ConstPtr = std::shared_ptr<const DepthImageFusion>;

  /// Throws ConfigError for an invalid config.
  explicit DepthImageFusion(const DepthFusionConfig& config = {}) { setConfig(config); }
  /// Throws ConfigError for an invalid config.
  void setConfig(const DepthFusionConfig& config);
  const DepthFusionConfig& getConfig() const { return config_; }
  /// f B and the LiDAR's mounting over the camera. Throws CalibrationError without a baseline.
  void setCalibration(const Calibration& calibration);
  /// Optional grey image of camera 0 (CV_8UC1, the depth images' size), for the next fuse():
  /// with it and fusion.facade_extension, a LiDAR-backed wall goes on upward over the blank
  /// pixels above it (extendFacades); with fusion.clear_sky and a colour sky image, camera 0's
  /// own sky decides the clear sky withheld near an edge (withholdClearSky). Empty: nothing
  /// after the fusion but edge support.
  void setInputImage(const cv::Mat& left) { left_ = left; }
  /// Optional image of camera 0's view to find the open sky in (CV_8UC3 BGR, the colour
  /// camera's at camera 0's pixels, which tells a blue sky from a white wall; or CV_8UC1 grey),
  /// for the next fuse(): with it and fusion.clear_sky, no depth in the clear sky, nor in the
  /// open sky in front of its column's returns (withholdClearSky). Empty: none withheld.
  void setSkyImage(const cv::Mat& image) { sky_image_ = image; }
  /// The open sky (SkyMask, CV_8UC1, 255 = sky) the last fuse() found; empty when it had no sky
  /// image or clear_sky is off.
  const cv::Mat& getOpenSky() const { return open_sky_; }
  /// The open sky in the last fuse()'s sky image: `sky` (CV_8UC1, 255 = sky), getOpenSky()'s
  /// when clear_sky found it, else found now (SkyMask); and `sky_depth` (CV_32FC1, skyDepthImage),
  /// how far each of its rays is carved (TsdfIntegrator::carveSky): NaN off the sky, the depth of
  /// its column's highest LiDAR return (SkyMask::topReturnDepth), +inf in its clear pixels
  /// (withholdClearSky's: rays that nothing but the sky stopped) and where the column has no
  /// return. Both empty without a sky image.
  void findOpenSky(cv::Mat& sky, cv::Mat& sky_depth) const;
  /// The last fuse()'s depth with its small holes filled at weight 0 (fusion.hole_fill_px,
  /// msf::fillSmallHoles), never in its open sky (findOpenSky's): the depth the engine gives once
  /// the map took the frame. fused_weight and free_space_weight, when given, are fuse()'s.
  void fillSmallHoles(cv::Mat& fused_depth, cv::Mat* fused_weight = nullptr,
                      cv::Mat* free_space_weight = nullptr) const;

  /// lidar_depth, stereo_depth: CV_32FC1 metres (0, negative or NaN = none); lidar_distance: CV_32FC1
  /// pixels to the nearest real return (empty: all 0); stereo_confidence: CV_32FC1 in [0, 1]
  /// (empty: all 1); all of one size. Writes fused_depth (CV_32FC1, 0 = none) and, when
  /// given, fused_weight and free_space_weight (CV_32FC1, FusionResult). Throws
  /// InvalidInputError naming the image whose type or size is wrong (setInputImage's and
  /// setSkyImage's too),
  /// CalibrationError when no calibration was set.
  void fuse(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
            const cv::Mat& stereo_confidence, cv::Mat& fused_depth, cv::Mat* fused_weight = nullptr,
            cv::Mat* free_space_weight = nullptr);

private:
  /// findOpenSky's mask alone (empty without a sky image).
  cv::Mat openSkyMask() const;

  DepthFusionConfig config_;
  double focal_baseline_{0.0};
  Calibration calibration_;
  LidarParallax parallax_;
  cv::Mat left_;                        ///< setInputImage's
  cv::Mat sky_image_, open_sky_;        ///< setSkyImage's, and the last fuse's open sky
  cv::Mat clear_sky_;                   ///< the last fuse's clear sky
  cv::Mat returns_;                     ///< the last fuse's real LiDAR returns, with a sky image
  SkyMask sky_;
  cv::Mat edge_;                        ///< the LiDAR's edge cue, kept between frames
  cv::Mat weight_, free_weight_;        ///< weights when the caller wants none
  cv::Mat zeros_, ones_;                ///< distances and confidences when the caller gives none
  EdgeSupportBuffers edge_buffers_;
};

/// One-call form of DepthImageFusion (buffers are allocated for the call).
void fuseDepthImages(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
                     const cv::Mat& stereo_confidence, const Calibration& calibration,
                     const DepthFusionConfig& config, cv::Mat& fused_depth, cv::Mat* fused_weight = nullptr);

} // namespace msf
