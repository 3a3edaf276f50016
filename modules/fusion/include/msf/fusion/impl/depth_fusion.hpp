// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/fusion_model.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/fused_canvas.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/impl/pinhole_camera.hpp>
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
  image_fusion_.setCalibration(calibration); // throws CalibrationError without a baseline
  calibration_ = calibration;
  has_calibration_ = true;
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::fuse(PointCloudOut& output) {
  checkInputs();
  readImages();
  fuseImages();
  writePoints(output);
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::checkInputs() {
  const auto size = [](const auto& cloud) { return std::to_string(cloud.width) + "x" + std::to_string(cloud.height); };
  if (!lidar_ || lidar_->empty())
    throw InvalidInputError("DepthFusion: the LiDAR cloud is missing or empty (setInputLidar)");
  if (!stereo_ || stereo_->empty())
    throw InvalidInputError("DepthFusion: the stereo cloud is missing or empty (setInputStereo)");
  if (!lidar_->isOrganized())
    throw InvalidInputError("DepthFusion: the LiDAR cloud is not organized (" + size(*lidar_) + ")");
  if (!stereo_->isOrganized())
    throw InvalidInputError("DepthFusion: the stereo cloud is not organized (" + size(*stereo_) + ")");
  const cv::Size lidar_size(static_cast<int>(lidar_->width), static_cast<int>(lidar_->height));
  const cv::Size image_size(static_cast<int>(stereo_->width), static_cast<int>(stereo_->height));
  try {
    image_in_canvas_ = imageInCanvas(lidar_size, image_size, "the LiDAR cloud");
  } catch (const InvalidInputError&) {
    throw InvalidInputError("DepthFusion: the LiDAR cloud is " + size(*lidar_) + " but the stereo cloud is " +
                            size(*stereo_) + " (the LiDAR's must be the stereo's size, or its canvas: that size "
                            "with a margin on every side)");
  }
  if (!has_calibration_)
    throw CalibrationError("DepthFusion: no calibration set (setCalibration)");
  // A stereo cloud of another size than the rig's images would be fused at shifted pixels.
  const cv::Size rig_size = calibration_.image_size;
  if (rig_size.area() > 0 && image_size != rig_size)
    throw InvalidInputError("DepthFusion: the stereo cloud is " + size(*stereo_) + " but calibration '" +
                            calibration_.source + "' is " + std::to_string(rig_size.width) + "x" +
                            std::to_string(rig_size.height));
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
  // Clouds of another rig of the same size would be fused, and integrated, at other rays.
  if (rig_size.area() > 0) {
    const PinholeCamera image = PinholeCamera::fromCalibration(calibration_);
    const std::string rig = "the left camera of calibration '" + calibration_.source + "'";
    requireCameraOfPoints(fitPinhole(*stereo_), image, "DepthFusion: the stereo cloud", rig);
    requireCameraOfPoints(fitPinhole(*lidar_),
                          image_in_canvas_.empty() ? image : image.onCanvas(image_in_canvas_, lidar_size),
                          "DepthFusion: the LiDAR cloud", rig);
  }
  // A NaN confidence would become a NaN weight, which the map takes as none.
  if constexpr (detail::has_confidence_v<PointStereoT>)
    for (std::size_t i = 0; i < stereo_->size(); ++i) {
      const PointStereoT& p = (*stereo_)[i];
      if (detail::validDepth(p.z) && !(p.confidence >= 0.f && p.confidence <= 1.f))
        throw InvalidInputError("DepthFusion: the stereo cloud's confidence at pixel (" +
                                std::to_string(i % stereo_->width) + ", " + std::to_string(i / stereo_->width) +
                                ") is " + std::to_string(p.confidence) + "; a depth's confidence is 0..1");
    }
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::readImages() {
  const int rows = static_cast<int>(lidar_->height), cols = static_cast<int>(lidar_->width);
  lidar_depth_.create(rows, cols, CV_32FC1);
  lidar_distance_.create(rows, cols, CV_32FC1); // 0 (a real return) for a type without distances
  const int image_rows = static_cast<int>(stereo_->height), image_cols = static_cast<int>(stereo_->width);
  stereo_depth_.create(image_rows, image_cols, CV_32FC1);
  if constexpr (detail::has_confidence_v<PointStereoT>)
    stereo_confidence_.create(image_rows, image_cols, CV_32FC1);
  else
    stereo_confidence_.release(); // every match counts as confident
  // cv::parallel_for_ rather than OpenMP: its work stealing keeps both cores busy when the
  // machine is shared, where a static OpenMP split waits for the slower thread.
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const PointLidarT* in = &(*lidar_)[static_cast<std::size_t>(v) * cols];
      float* z = lidar_depth_.ptr<float>(v);
      float* distance = lidar_distance_.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        z[u] = detail::validDepth(in[u].z) ? in[u].z : 0.f;
        if constexpr (detail::has_distance_v<PointLidarT>)
          distance[u] = in[u].distance;
        else
          distance[u] = 0.f;
      }
    }
  });
  parallelFor(cv::Range(0, image_rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const PointStereoT* in = &(*stereo_)[static_cast<std::size_t>(v) * image_cols];
      float* z = stereo_depth_.ptr<float>(v);
      for (int u = 0; u < image_cols; ++u)
        z[u] = detail::validDepth(in[u].z) ? in[u].z : 0.f;
      if constexpr (detail::has_confidence_v<PointStereoT>) {
        float* confidence = stereo_confidence_.ptr<float>(v);
        for (int u = 0; u < image_cols; ++u)
          confidence[u] = in[u].confidence;
      }
    }
  });
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::fuseImages() {
  const cv::Size size = stereo_depth_.size();
  const bool on_canvas = !image_in_canvas_.empty();
  const cv::Mat lidar = on_canvas ? lidar_depth_(image_in_canvas_).clone() : lidar_depth_;
  const cv::Mat distance = on_canvas ? lidar_distance_(image_in_canvas_).clone() : lidar_distance_;
  image_fusion_.setConfig(config_);
  image_fusion_.setInputImage(left_);
  image_fusion_.setSkyImage(skyImage(color_, left_, size));
  image_fusion_.fuse(lidar, distance, stereo_depth_, stereo_confidence_, fused_depth_, &fused_weight_,
                     &fused_free_weight_);
  if constexpr (detail::has_sky_depth_v<PointOutT>)
    image_fusion_.findOpenSky(sky_, sky_depth_);
  // The colour camera's at the fused points, as the pipeline colours them (camera 0's grey where
  // that camera does not see); without it, or where neither has a colour, the stereo points'.
  if (color_.empty() || left_.empty())
    readStereoColours(fused_color_);
  if (!color_.empty()) {
    PinholeCamera camera;
    camera.fx = static_cast<float>(calibration_.fx()), camera.fy = static_cast<float>(calibration_.fy());
    camera.cx = static_cast<float>(calibration_.cx()), camera.cy = static_cast<float>(calibration_.cy());
    camera.width = size.width, camera.height = size.height;
    const cv::Mat fallback = left_.empty() ? fused_color_.clone() : left_;
    colorizeDepth(fused_depth_, camera, ColorSampler(color_, calibration_, color_camera_), fallback, fused_color_);
  }
  if (on_canvas)
    growOntoCanvas(lidar_depth_, lidar_distance_, config_, static_cast<float>(calibration_.focalBaseline()),
                   fused_depth_, fused_weight_, fused_free_weight_, &fused_color_);
  if (fill_small_holes_) {
    // The image's holes, after the canvas grew from the fusion's own depth (as the engine's).
    const cv::Rect image = on_canvas ? image_in_canvas_ : cv::Rect(cv::Point(), size);
    cv::Mat depth = fused_depth_(image), weight = fused_weight_(image), free_weight = fused_free_weight_(image);
    image_fusion_.fillSmallHoles(depth, &weight, &free_weight);
  }
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::readStereoColours(cv::Mat& bgr) const {
  const int rows = static_cast<int>(stereo_->height), cols = static_cast<int>(stereo_->width);
  bgr.create(rows, cols, CV_8UC3);
  if constexpr (!detail::has_rgb_v<PointStereoT>) {
    bgr.setTo(cv::Scalar::all(0));
  } else {
    for (int v = 0; v < rows; ++v) {
      const PointStereoT* in = &(*stereo_)[static_cast<std::size_t>(v) * cols];
      cv::Vec3b* out = bgr.ptr<cv::Vec3b>(v);
      for (int u = 0; u < cols; ++u)
        out[u] = cv::Vec3b(in[u].b, in[u].g, in[u].r);
    }
  }
}

template <typename PointLidarT, typename PointStereoT, typename PointOutT>
void DepthFusion<PointLidarT, PointStereoT, PointOutT>::writePoints(PointCloudOut& output) const {
  const int rows = fused_depth_.rows, cols = fused_depth_.cols;
  const cv::Rect image = image_in_canvas_.empty() ? cv::Rect(0, 0, cols, rows) : image_in_canvas_;
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
  const float cx = static_cast<float>(calibration_.cx()) + static_cast<float>(image.x);
  const float cy = static_cast<float>(calibration_.cy()) + static_cast<float>(image.y);
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    bool range_dense = true;
    for (int v = range.start; v < range.end; ++v) {
      const float* fused_z = fused_depth_.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        PointOutT& p = output[static_cast<std::size_t>(v) * cols + u];
        const bool in_image = image.contains(cv::Point(u, v));
        const PointStereoT* s = in_image ? &stereo_->at(u - image.x, v - image.y) : nullptr;
        const float z = fused_z[u];
        if (z > 0.f) {
          // On the ray of the input point: stereo's lies on the pixel's ray, the LiDAR's
          // within half a pixel of it.
          const bool from_stereo = s && detail::validDepth(s->z);
          const PointLidarT& l = lidar_->at(u, v);
          if (from_stereo || detail::validDepth(l.z)) {
            const float scale = z / (from_stereo ? s->z : l.z);
            p.x = (from_stereo ? s->x : l.x) * scale;
            p.y = (from_stereo ? s->y : l.y) * scale;
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
          const cv::Vec3b& bgr = fused_color_.at<cv::Vec3b>(v, u);
          p.b = bgr[0];
          p.g = bgr[1];
          p.r = bgr[2];
          p.a = 255;
        }
        if constexpr (detail::has_weight_v<PointOutT>)
          p.weight = fused_weight_.at<float>(v, u);
        if constexpr (detail::has_free_space_weight_v<PointOutT>)
          p.free_space_weight = fused_free_weight_.at<float>(v, u);
        if constexpr (detail::has_sky_depth_v<PointOutT>)
          p.sky_depth = in_image && !sky_depth_.empty() ? sky_depth_.at<float>(v - image.y, u - image.x) : nan;
      }
    }
    if (!range_dense)
      dense = false;
  });
  output.is_dense = dense;
}

} // namespace msf
