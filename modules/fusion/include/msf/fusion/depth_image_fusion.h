#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/io/calibration.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// DepthFusion on images, for pipelines that keep depth images between stages (the
/// evaluation, the TSDF integrator): the same per-pixel model (fusion_model.h), without
/// clouds. lidar_depth, stereo_depth: CV_32FC1 metres (0 or NaN = none); lidar_distance:
/// CV_32FC1 pixels to the nearest real return (empty: all 0); stereo_confidence: CV_32FC1
/// in [0, 1] (empty: all 1); all of one size. `calibration` gives f B and the LiDAR's
/// mounting over the camera. Writes fused_depth (CV_32FC1, 0 = none) and, when given,
/// fused_weight (CV_32FC1). Throws InvalidInputError naming the image whose type or size is
/// wrong, CalibrationError when the calibration has no baseline, ConfigError for an invalid
/// config.
void fuseDepthImages(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
                     const cv::Mat& stereo_confidence, const Calibration& calibration,
                     const DepthFusionConfig& config, cv::Mat& fused_depth, cv::Mat* fused_weight = nullptr);

} // namespace msf
