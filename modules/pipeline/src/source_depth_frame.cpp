// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/fused_canvas.h>
#include <msf/fusion/fusion_model.h>
#include <msf/io/pinhole_camera.h>
#include <msf/pipeline/source_depth_frame.h>

#include <opencv2/core.hpp>

#include <cmath>

namespace msf {

namespace {

std::string frameName(const FrameResult& result) {
  return result.name.empty() ? std::to_string(result.index) : result.name;
}

/// Where the image lies in the LiDAR's canvas of `result`, or an empty rectangle when the
/// frame has no canvas around its image.
cv::Rect imageInCanvas(const FrameResult& result, const cv::Size& image) {
  const cv::Mat& canvas = result.lidar_canvas_depth;
  if (canvas.empty())
    return {};
  const std::string what = "frame " + frameName(result) + "'s LiDAR canvas";
  const cv::Rect in_canvas = msf::imageInCanvas(canvas.size(), image, what);
  if (!in_canvas.empty() && (canvas.type() != CV_32FC1 || result.lidar_canvas_distance.size() != canvas.size() ||
                             result.lidar_canvas_camera.width != canvas.cols ||
                             result.lidar_canvas_camera.height != canvas.rows))
    throw InvalidInputError(what + " has no distance image or camera of its size");
  return in_canvas;
}

void requireBaseline(double focal_baseline) {
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("the frames for integration need f B > 0, got " + std::to_string(focal_baseline));
}

} // namespace

DepthFrame fusedDepthFrame(const FrameResult& result, const DepthFusionConfig& fusion, double focal_baseline) {
  requireBaseline(focal_baseline);
  if (imageInCanvas(result, result.fused.depth.size()).empty())
    return result.fused;
  DepthFrame frame = result.fused;
  frame.camera = result.lidar_canvas_camera;
  growOntoCanvas(result.lidar_canvas_depth, result.lidar_canvas_distance, fusion, static_cast<float>(focal_baseline),
                 frame.depth, frame.weight, frame.free_space_weight, &frame.color);
  return frame;
}

const char* toString(DepthSource source) { return source == DepthSource::Lidar ? "lidar" : "stereo"; }

DepthFrame sourceDepthFrame(const FrameResult& result, DepthSource source, const DepthFusionConfig& fusion,
                            double focal_baseline) {
  const bool lidar = source == DepthSource::Lidar;
  const cv::Mat& depth = lidar ? result.lidar_depth : result.stereo_depth;
  const cv::Mat& cue = lidar ? result.lidar_distance : result.stereo_confidence;
  if (depth.empty() || depth.type() != CV_32FC1)
    throw InvalidInputError("frame " + frameName(result) + " has no " + toString(source) + " depth image");
  if (!cue.empty() && (cue.type() != CV_32FC1 || cue.size() != depth.size()))
    throw InvalidInputError("frame " + frameName(result) + "'s " + (lidar ? "LiDAR distance" : "stereo confidence") +
                            " image is not CV_32FC1 of the depth's size");
  if (result.fused.color.empty())
    throw InvalidInputError("frame " + frameName(result) + " has no fused colour to integrate its " +
                            toString(source) + " depth with");
  requireBaseline(focal_baseline);
  const float fb = static_cast<float>(focal_baseline);
  DepthFrame out;
  if (lidar) {
    // The LiDAR alone has no stereo to settle its edges (returns seen past a foreground edge,
    // interpolation across one): its weight counts the edge cue too, as the
    // fusion's sigma does. On its canvas, as the fused frame.
    const cv::Rect image = imageInCanvas(result, depth.size());
    const cv::Mat& canvas = image.empty() ? depth : result.lidar_canvas_depth;
    const cv::Mat& distance = image.empty() ? cue : result.lidar_canvas_distance;
    cv::Mat range;
    lidarEdgeCue(canvas, focal_baseline, fusion, range);
    out.depth = canvas;
    out.weight = lidarWeightImage(canvas, distance, range, fusion, fb);
    out.camera = image.empty() ? result.fused.camera : result.lidar_canvas_camera;
    out.color = image.empty() ? result.fused.color : repeatBorderOntoCanvas(result.fused.color, image, canvas.size());
  } else {
    out.depth = depth;
    out.color = result.fused.color;
    out.camera = result.fused.camera;
    out.weight.create(depth.size(), CV_32FC1);
    for (int v = 0; v < depth.rows; ++v) {
      const float* z = depth.ptr<float>(v);
      const float* c = cue.empty() ? nullptr : cue.ptr<float>(v);
      float* w = out.weight.ptr<float>(v);
      for (int u = 0; u < depth.cols; ++u) {
        const float sigma = stereoSigmaPx(c ? c[u] : 1.f, fusion);
        w[u] = std::isfinite(z[u]) && z[u] > 0.f ? depthWeight(z[u], 1.f / (sigma * sigma), fb) : 0.f;
      }
    }
  }
  out.validate();
  return out;
}

} // namespace msf
