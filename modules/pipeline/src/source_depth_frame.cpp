#include <msf/common/exceptions.h>
#include <msf/pipeline/source_depth_frame.h>

#include <opencv2/core.hpp>

#include <cmath>

namespace msf {

const char* toString(DepthSource source) { return source == DepthSource::Lidar ? "lidar" : "stereo"; }

DepthFrame sourceDepthFrame(const FrameResult& result, DepthSource source) {
  const cv::Mat& depth = source == DepthSource::Lidar ? result.lidar_depth : result.stereo_depth;
  const std::string frame = result.name.empty() ? std::to_string(result.index) : result.name;
  if (depth.empty() || depth.type() != CV_32FC1)
    throw InvalidInputError(std::string("frame ") + frame + " has no " + toString(source) + " depth image");
  if (result.fused.color.empty())
    throw InvalidInputError("frame " + frame + " has no fused colour to integrate its " + toString(source) + " depth with");
  DepthFrame out;
  out.depth = depth;
  out.color = result.fused.color;
  out.camera = result.fused.camera;
  out.weight.create(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    float* w = out.weight.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      w[u] = std::isfinite(z[u]) && z[u] > 0.f ? 1.f : 0.f;
  }
  out.validate();
  return out;
}

} // namespace msf
