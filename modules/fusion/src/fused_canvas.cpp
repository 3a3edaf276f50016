// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/fused_canvas.h>
#include <msf/fusion/fusion_model.h>
#include <msf/io/pinhole_camera.h>

#include <opencv2/core.hpp>

#include <cmath>

namespace msf {

cv::Mat lidarWeightImage(const cv::Mat& depth, const cv::Mat& distance, const cv::Mat& range,
                         const DepthFusionConfig& fusion, float focal_baseline) {
  cv::Mat weight(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    const float* d = distance.empty() ? nullptr : distance.ptr<float>(v);
    const float* r = range.empty() ? nullptr : range.ptr<float>(v);
    float* w = weight.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      const float error_px =
          fusion.lidar_sigma_per_distance * (d ? d[u] : 0.f) + fusion.lidar_sigma_per_range * (r ? r[u] : 0.f);
      w[u] = std::isfinite(z[u]) && z[u] > 0.f ? lidarDepthWeight(z[u], error_px, focal_baseline, fusion) : 0.f;
    }
  }
  return weight;
}

cv::Mat repeatBorderOntoCanvas(const cv::Mat& image, const cv::Rect& image_in_canvas, const cv::Size& canvas) {
  cv::Mat grown;
  cv::copyMakeBorder(image, grown, image_in_canvas.y, canvas.height - image_in_canvas.br().y, image_in_canvas.x,
                     canvas.width - image_in_canvas.br().x, cv::BORDER_REPLICATE);
  return grown;
}

void growOntoCanvas(const cv::Mat& canvas_depth, const cv::Mat& canvas_distance, const DepthFusionConfig& fusion,
                    float focal_baseline, cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight,
                    cv::Mat* color) {
  const cv::Rect image = imageInCanvas(canvas_depth.size(), depth.size(), "the LiDAR's canvas");
  if (image.empty())
    return;
  if (canvas_depth.type() != CV_32FC1 || canvas_distance.size() != canvas_depth.size())
    throw InvalidInputError("the LiDAR's canvas must be CV_32FC1 with a distance image of its size");
  cv::Mat grown_depth = canvas_depth.clone();
  cv::Mat grown_weight = lidarWeightImage(grown_depth, canvas_distance, cv::Mat(), fusion, focal_baseline);
  depth.copyTo(grown_depth(image));
  if (!free_space_weight.empty()) { // around the image, the LiDAR's own weight
    cv::Mat grown_free = grown_weight.clone();
    free_space_weight.copyTo(grown_free(image));
    free_space_weight = grown_free;
  }
  weight.copyTo(grown_weight(image));
  depth = grown_depth;
  weight = grown_weight;
  if (color && !color->empty())
    *color = repeatBorderOntoCanvas(*color, image, canvas_depth.size());
}

} // namespace msf
