#include <msf/common/exceptions.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/fusion_model.h>

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

void fuseDepthImages(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance, const cv::Mat& stereo_depth,
                     const cv::Mat& stereo_confidence, const Calibration& calibration,
                     const DepthFusionConfig& config, cv::Mat& fused_depth, cv::Mat* fused_weight) {
  config.validate();
  if (lidar_depth.empty())
    throw InvalidInputError("depth fusion: the LiDAR depth image is empty");
  const cv::Size size = lidar_depth.size();
  check(lidar_depth, "the LiDAR depth image", size, false);
  check(lidar_distance, "the LiDAR distance image", size, true);
  check(stereo_depth, "the stereo depth image", size, false);
  check(stereo_confidence, "the stereo confidence image", size, true);
  const double focal_baseline = calibration.focalBaseline();
  if (!(focal_baseline > 0.0))
    throw CalibrationError("calibration '" + calibration.source +
                           "': the grey pair has no baseline (P1 must hold -f B in its last column)");
  const LidarParallax parallax = lidarParallax(calibration, config);

  cv::Mat range;
  if (config.method == FusionMethod::Uncertainty)
    localDisparityRange(lidar_depth, focal_baseline, config.lidar_range_window_px, range);
  fused_depth.create(size, CV_32FC1);
  if (fused_weight)
    fused_weight->create(size, CV_32FC1);
  const float fB = static_cast<float>(focal_baseline);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v) {
      const float* zl = lidar_depth.ptr<float>(v);
      const float* dist = lidar_distance.empty() ? nullptr : lidar_distance.ptr<float>(v);
      const float* rng = range.empty() ? nullptr : range.ptr<float>(v);
      const float* zs = stereo_depth.ptr<float>(v);
      const float* conf = stereo_confidence.empty() ? nullptr : stereo_confidence.ptr<float>(v);
      float* out = fused_depth.ptr<float>(v);
      float* weight = fused_weight ? fused_weight->ptr<float>(v) : nullptr;
      for (int u = 0; u < size.width; ++u) {
        FusionInputs in;
        in.z_lidar = detail::validDepth(zl[u]) ? zl[u] : 0.f;
        in.lidar_distance = dist ? dist[u] : 0.f;
        in.lidar_range_px = rng ? rng[u] : 0.f;
        in.z_stereo = detail::validDepth(zs[u]) ? zs[u] : 0.f;
        in.stereo_confidence = conf ? conf[u] : 1.f;
        const FusionResult f = fusePixel(in, config, fB, parallax, [&](int k) {
          return v + k < size.height ? lidar_depth.ptr<float>(v + k)[u] : 0.f;
        });
        out[u] = f.z;
        if (weight)
          weight[u] = f.weight;
      }
    }
  });
}

} // namespace msf
