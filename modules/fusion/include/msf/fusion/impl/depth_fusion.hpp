// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/fusion_model.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/facade_extension.h>
#include <msf/range_image/real_returns.h>
#include <msf/stereo/color_sampler.h>
#include <msf/stereo/point_field_traits.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace msf {

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::setCalibration(const Calibration& calibration) {
  if (!(calibration.focalBaseline() > 0.0))
    throw CalibrationError("calibration '" + calibration.source +
                           "': the grey pair has no baseline (P1 must hold -f B in its last column)");
  calibration_ = calibration;
  has_calibration_ = true;
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::fuse(PointCloudOut& output) {
  checkInputs();
  readLidarImages();
  fuseImages();
  writePoints(output);
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::checkInputs() const {
  const auto size = [](const auto& cloud) { return std::to_string(cloud.width) + "x" + std::to_string(cloud.height); };
  if (!lidar_ || lidar_->empty())
    throw InvalidInputError("DepthFusion: the LiDAR cloud is missing or empty (setInputLidar)");
  if (!stereo_ || stereo_->empty())
    throw InvalidInputError("DepthFusion: the stereo cloud is missing or empty (setInputStereo)");
  if (!lidar_->isOrganized())
    throw InvalidInputError("DepthFusion: the LiDAR cloud is not organized (" + size(*lidar_) + ")");
  if (!stereo_->isOrganized())
    throw InvalidInputError("DepthFusion: the stereo cloud is not organized (" + size(*stereo_) + ")");
  if (lidar_->width != stereo_->width || lidar_->height != stereo_->height)
    throw InvalidInputError("DepthFusion: the LiDAR cloud is " + size(*lidar_) + " but the stereo cloud is " +
                            size(*stereo_));
  if (!has_calibration_)
    throw CalibrationError("DepthFusion: no calibration set (setCalibration)");
  // A finite depth beyond any sensor's range (1e30 m) is a broken input: it would pass
  // through the fusion as a depth, so it is an error naming the cloud and the pixel.
  const auto checkRange = [](const auto& cloud, const char* what) {
    for (std::size_t i = 0; i < cloud.size(); ++i)
      if (std::isfinite(cloud[i].z) && !(std::abs(cloud[i].z) <= limits::kMaxDepthM))
        throw InvalidInputError(std::string("DepthFusion: the ") + what + " cloud has a depth of " +
                                std::to_string(cloud[i].z) + " m at pixel (" + std::to_string(i % cloud.width) + ", " +
                                std::to_string(i / cloud.width) + "), beyond " + std::to_string(limits::kMaxDepthM) +
                                " m");
  };
  checkRange(*lidar_, "LiDAR");
  checkRange(*stereo_, "stereo");
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::readLidarImages() {
  const int rows = static_cast<int>(lidar_->height), cols = static_cast<int>(lidar_->width);
  lidar_depth_.create(rows, cols, CV_32FC1);
  if constexpr (detail::has_distance_v<PointLidarT>)
    lidar_distance_.create(rows, cols, CV_32FC1);
  else
    lidar_distance_.release(); // every LiDAR depth counts as a real return
  // cv::parallel_for_ rather than OpenMP: its work stealing keeps both cores busy when the
  // machine is shared, where a static OpenMP split waits for the slower thread.
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const PointLidarT* in = &(*lidar_)[static_cast<std::size_t>(v) * cols];
      float* z = lidar_depth_.ptr<float>(v);
      for (int u = 0; u < cols; ++u)
        z[u] = detail::validDepth(in[u].z) ? in[u].z : 0.f;
      if constexpr (detail::has_distance_v<PointLidarT>) {
        float* distance = lidar_distance_.ptr<float>(v);
        for (int u = 0; u < cols; ++u)
          distance[u] = in[u].distance;
      }
    }
  });
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::fuseImages() {
  const int rows = static_cast<int>(stereo_->height), cols = static_cast<int>(stereo_->width);
  const float fB = static_cast<float>(calibration_.focalBaseline());
  const bool uncertainty = config_.method == FusionMethod::Uncertainty;
  if (uncertainty)
    lidarEdgeCue(lidar_depth_, fB, config_, lidar_edge_);
  const DepthFusionConfig config = config_;
  const LidarParallax parallax = lidarParallax(calibration_, config);
  // A row at a time in contiguous arrays for fuseRow.
  fused_depth_.create(rows, cols, CV_32FC1);
  fused_weight_.create(rows, cols, CV_32FC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<float> zeros(static_cast<std::size_t>(cols), 0.f), z_stereo(zeros), confidence(zeros), free(zeros);
    for (int v = range.start; v < range.end; ++v) {
      const std::size_t row = static_cast<std::size_t>(v) * cols;
      for (int u = 0; u < cols; ++u) {
        const PointStereoT& s = (*stereo_)[row + u];
        z_stereo[u] = detail::validDepth(s.z) ? s.z : 0.f;
        if constexpr (detail::has_confidence_v<PointStereoT>)
          confidence[u] = s.confidence;
        else
          confidence[u] = 1.f;
      }
      fuseRow(config, fB, parallax, lidar_depth_, v, lidar_distance_.empty() ? zeros.data() : lidar_distance_.ptr<float>(v),
              uncertainty ? lidar_edge_.ptr<float>(v) : zeros.data(), z_stereo.data(), confidence.data(),
              fused_depth_.ptr<float>(v), fused_weight_.ptr<float>(v), free.data());
    }
  });
  if (config.edge_support)
    supportAtDepthEdges(lidar_depth_, lidar_distance_, fB, config, fused_depth_, edge_buffers_);
  if (config.facade_extension && !left_.empty()) {
    cv::Mat no_free_space;
    extendFacades(left_, calibration_, config, fused_depth_, fused_weight_, no_free_space);
  }
  const cv::Mat& sky_image = skyImage(color_, left_, cv::Size(cols, rows));
  if (config.clear_sky && !sky_image.empty()) {
    cv::Mat no_free_space;
    withholdClearSky(SkyMask(), sky_image,
                     lidar_distance_.empty() ? lidar_depth_ : realReturns(lidar_depth_, lidar_distance_), fused_depth_,
                     fused_weight_, no_free_space);
  }
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::writePoints(PointCloudOut& output) const {
  const ColorSampler sampler = color_.empty() ? ColorSampler() : ColorSampler(color_, calibration_, color_camera_);
  const int rows = static_cast<int>(stereo_->height), cols = static_cast<int>(stereo_->width);
  output.resize(static_cast<std::size_t>(rows) * cols);
  output.width = static_cast<std::uint32_t>(cols);
  output.height = static_cast<std::uint32_t>(rows);
  // The stereo cloud's header (camera 0); SGBM works on images that carry no stamp, so the
  // LiDAR's, the scan's carried through projection, fills one the stereo cloud lacks.
  output.header = stereo_->header;
  if (output.header.stamp == 0)
    output.header.stamp = lidar_->header.stamp;
  if (output.header.frame_id.empty())
    output.header.frame_id = lidar_->header.frame_id;
  output.sensor_origin_ = stereo_->sensor_origin_;
  output.sensor_orientation_ = stereo_->sensor_orientation_;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Where neither input has a point (a wall the extension continued), the pixel's own ray.
  const float fx = static_cast<float>(calibration_.fx()), fy = static_cast<float>(calibration_.fy());
  const float cx = static_cast<float>(calibration_.cx()), cy = static_cast<float>(calibration_.cy());
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    bool range_dense = true;
    for (int v = range.start; v < range.end; ++v) {
      const std::size_t row = static_cast<std::size_t>(v) * cols;
      const float* fused_z = fused_depth_.ptr<float>(v);
      const float* fused_weight = fused_weight_.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        const PointStereoT& s = (*stereo_)[row + u];
        PointOutT& p = output[row + u];
        const float z = fused_z[u];
        if (z > 0.f) {
          // On the ray of the input point: stereo's lies on the pixel's ray, the LiDAR's
          // within half a pixel of it.
          const bool from_stereo = detail::validDepth(s.z);
          const PointLidarT& l = (*lidar_)[row + u];
          if (from_stereo || detail::validDepth(l.z)) {
            const float scale = z / (from_stereo ? s.z : l.z);
            p.x = (from_stereo ? s.x : l.x) * scale;
            p.y = (from_stereo ? s.y : l.y) * scale;
          } else {
            p.x = (static_cast<float>(u) - cx) * z / fx;
            p.y = (static_cast<float>(v) - cy) * z / fy;
          }
          p.z = z;
        } else {
          p.x = p.y = p.z = nan;
          range_dense = false;
        }
        if constexpr (detail::has_rgb_v<PointOutT>) {
          if constexpr (detail::has_rgb_v<PointStereoT>) {
            p.r = s.r;
            p.g = s.g;
            p.b = s.b;
          } else {
            p.r = p.g = p.b = 0;
          }
          p.a = 255;
          if (z > 0.f)
            sampler.sample(p.x, p.y, p.z, p.r, p.g, p.b);
        }
        if constexpr (detail::has_weight_v<PointOutT>)
          p.weight = fused_weight[u];
      }
    }
    if (!range_dense)
      dense = false;
  });
  output.is_dense = dense;
}

} // namespace msf
