// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/range_image/distance_transform.h>
#include <msf/range_image/lidar_completion.h>

#include <algorithm>
#include <cmath>

namespace msf {

CompletionMethod parseCompletionMethod(const std::string& name) {
  if (name == "compound" || name == "interpolated")
    return CompletionMethod::Compound;
  if (name == "linear")
    return CompletionMethod::Linear;
  if (name == "cubic")
    return CompletionMethod::Cubic;
  if (name == "ipbasic")
    return CompletionMethod::IpBasicFast;
  if (name == "ipbasic_multiscale")
    return CompletionMethod::IpBasicMultiscale;
  throw InvalidInputError("method '" + name + "' is not compound, linear, cubic, ipbasic or ipbasic_multiscale");
}

const char* toString(CompletionMethod method) {
  switch (method) {
  case CompletionMethod::Linear:
    return "linear";
  case CompletionMethod::Cubic:
    return "cubic";
  case CompletionMethod::IpBasicFast:
    return "ipbasic";
  case CompletionMethod::IpBasicMultiscale:
    return "ipbasic_multiscale";
  default:
    return "compound";
  }
}

namespace {

InterpolationConfig withInterpolant(InterpolationConfig config, CompletionMethod method) {
  if (method == CompletionMethod::Linear)
    config.slice.interpolant = SliceInterpolant::Linear;
  else if (method == CompletionMethod::Cubic)
    config.slice.interpolant = SliceInterpolant::Cubic;
  return config;
}

bool isIpBasic(CompletionMethod method) {
  return method == CompletionMethod::IpBasicFast || method == CompletionMethod::IpBasicMultiscale;
}

/// Copies the pixels of `roi` of an organized cloud into `out`.
template <typename PointT>
void cropOrganized(const pcl::PointCloud<PointT>& in, const cv::Rect& roi, pcl::PointCloud<PointT>& out) {
  out.resize(static_cast<std::size_t>(roi.width) * roi.height);
  out.width = static_cast<std::uint32_t>(roi.width);
  out.height = static_cast<std::uint32_t>(roi.height);
  out.header = in.header;
  bool dense = true;
  for (int v = 0; v < roi.height; ++v) {
    const PointT* src = &in[static_cast<std::size_t>(v + roi.y) * in.width + roi.x];
    PointT* dst = &out[static_cast<std::size_t>(v) * roi.width];
    std::copy(src, src + roi.width, dst);
    for (int u = 0; u < roi.width && dense; ++u)
      dense = std::isfinite(dst[u].z);
  }
  out.is_dense = dense;
}

} // namespace

LidarCompletion::LidarCompletion(const Calibration& calibration, CompletionMethod method,
                                 const ProjectionConfig& projection, const InterpolationConfig& interpolation,
                                 const IpBasicConfig& ip_basic)
    : method_(method), projector_(calibration, projection), interpolator_(withInterpolant(interpolation, method)),
      ip_basic_(ip_basic), canvas_(new pcl::PointCloud<PointXYZID>) {
  ip_basic_.variant = method == CompletionMethod::IpBasicFast ? IpBasicVariant::Fast : IpBasicVariant::Multiscale;
  ip_basic_.validate();
  compound_filter_.setConfig(interpolator_.config());
  compound_filter_.setCamera(projector_.canvasCamera());
  compound_filter_.setInputCloud(canvas_);
  ip_basic_filter_.setConfig(ip_basic_);
  ip_basic_filter_.setCamera(projector_.canvasCamera());
  ip_basic_filter_.setInputCloud(canvas_);
}

void LidarCompletion::complete(const cv::Mat& sparse, cv::Mat& dense) {
  if (isIpBasic(method_))
    dense = ipBasic(sparse, ip_basic_);
  else
    interpolator_.interpolate(sparse, dense);
}

void LidarCompletion::computeDepth(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth, cv::Mat* distance) {
  projector_.projectToCanvas(scan, sparse_);
  complete(sparse_, dense_);
  const cv::Rect image = projector_.imageInCanvas();
  dense_(image).copyTo(depth);
  if (distance) {
    distanceToSamples(sparse_, distance_, nullptr, interpolator_.config().threads);
    distance_(image).copyTo(*distance);
  }
}

void LidarCompletion::compute(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointXYZID>& cloud) {
  computeCanvas(scan, canvas_out_);
  cropOrganized(canvas_out_, projector_.imageInCanvas(), cloud);
}

void LidarCompletion::computeCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointXYZID>& cloud) {
  projector_.projectCanvas(scan, *canvas_);
  if (isIpBasic(method_))
    ip_basic_filter_.filter(cloud);
  else
    compound_filter_.filter(cloud);
}

} // namespace msf
