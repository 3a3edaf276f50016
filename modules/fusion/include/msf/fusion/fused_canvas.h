// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// The LiDAR's weights of a depth image by the fusion's model (lidarDepthWeight): the inverse
/// variance of each depth from its interpolation error, the distance to the nearest real return
/// (`distance`, empty: 0) and, when given, the local disparity range (`range`, lidarEdgeCue).
/// CV_32FC1 of the depth's size, 0 where there is no depth.
cv::Mat lidarWeightImage(const cv::Mat& depth, const cv::Mat& distance, const cv::Mat& range,
                         const DepthFusionConfig& fusion, float focal_baseline);

/// An image of the camera's size (any type) grown onto the canvas that holds it at
/// `image_in_canvas`, its border pixels repeated over the margin: the colours around a frame.
cv::Mat repeatBorderOntoCanvas(const cv::Mat& image, const cv::Rect& image_in_canvas, const cv::Size& canvas);

/// The fused images grown onto the LiDAR's canvas (the image with the margin it was projected
/// with, projection.margin_px): the interpolated LiDAR fills the margin, weighed by
/// lidarWeightImage, its free space by the same weight. So the edge of what a frame adds to the
/// map (marching cubes needs voxels seen on both sides of a surface) lies outside the camera's
/// view rather than a voxel inside it. `depth`, `weight` and `free_space_weight` (image-sized,
/// CV_32FC1; the last may be empty) are replaced by canvas-sized ones, and so is `color` when
/// given (its border pixels repeated over the margin); nothing changes when the canvas is the
/// image's size. Throws InvalidInputError when the canvas is not the image with a
/// margin on every side, or its distance image another size.
void growOntoCanvas(const cv::Mat& canvas_depth, const cv::Mat& canvas_distance, const DepthFusionConfig& fusion,
                    float focal_baseline, cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight,
                    cv::Mat* color = nullptr);

} // namespace msf
