#include <msf/common/exceptions.h>
#include <msf/fusion/fusion_model.h>
#include <msf/pipeline/source_depth_frame.h>

#include <opencv2/core.hpp>

#include <cmath>

namespace msf {

const char* toString(DepthSource source) { return source == DepthSource::Lidar ? "lidar" : "stereo"; }

DepthFrame sourceDepthFrame(const FrameResult& result, DepthSource source, const DepthFusionConfig& fusion,
                            double focal_baseline) {
  const bool lidar = source == DepthSource::Lidar;
  const cv::Mat& depth = lidar ? result.lidar_depth : result.stereo_depth;
  const cv::Mat& cue = lidar ? result.lidar_distance : result.stereo_confidence;
  const std::string frame = result.name.empty() ? std::to_string(result.index) : result.name;
  if (depth.empty() || depth.type() != CV_32FC1)
    throw InvalidInputError(std::string("frame ") + frame + " has no " + toString(source) + " depth image");
  if (!cue.empty() && (cue.type() != CV_32FC1 || cue.size() != depth.size()))
    throw InvalidInputError(std::string("frame ") + frame + "'s " + (lidar ? "LiDAR distance" : "stereo confidence") +
                            " image is not CV_32FC1 of the depth's size");
  if (result.fused.color.empty())
    throw InvalidInputError("frame " + frame + " has no fused colour to integrate its " + toString(source) + " depth with");
  if (!(focal_baseline > 0.0))
    throw InvalidInputError("sourceDepthFrame needs f B > 0, got " + std::to_string(focal_baseline));
  DepthFrame out;
  out.depth = depth;
  out.color = result.fused.color;
  out.camera = result.fused.camera;
  // The LiDAR alone has no stereo to settle its edges (returns seen past a foreground edge,
  // interpolation across one): its weight counts the local disparity range too, as the
  // fusion's sigma does.
  cv::Mat range;
  if (lidar)
    localDisparityRange(depth, focal_baseline, fusion.lidar_range_window_px, range);
  const float fb = static_cast<float>(focal_baseline);
  out.weight.create(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    const float* c = cue.empty() ? nullptr : cue.ptr<float>(v);
    float* w = out.weight.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      const bool valid = std::isfinite(z[u]) && z[u] > 0.f;
      const float sigma = stereoSigmaPx(c ? c[u] : 1.f, fusion);
      w[u] = !valid ? 0.f
             : lidar ? lidarDepthWeight(z[u], lidarSigmaPx(c ? c[u] : 0.f, range.ptr<float>(v)[u], fusion) -
                                                  fusion.lidar_sigma_px, fb, fusion)
                     : depthWeight(z[u], 1.f / (sigma * sigma), fb);
    }
  }
  out.validate();
  return out;
}

} // namespace msf
