#pragma once
#include <msf/common/exceptions.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/point_types.h>

#include <pcl/type_traits.h>

#include <cmath>
#include <cstdint>
#include <string>

namespace msf {

namespace detail {

/// Least-squares fit of u = fx * x/z + cx and v = fy * y/z + cy over valid pixels.
struct PinholeFit {
  double n = 0, su = 0, sa = 0, saa = 0, sau = 0, suu = 0;
  double sv = 0, sb = 0, sbb = 0, sbv = 0, svv = 0;
  void add(int u, int v, float x, float y, float z) {
    const double a = x / z, b = y / z;
    n += 1;
    su += u; sa += a; saa += a * a; sau += a * u; suu += double(u) * u;
    sv += v; sb += b; sbb += b * b; sbv += b * v; svv += double(v) * v;
  }
  void merge(const PinholeFit& o) {
    n += o.n; su += o.su; sa += o.sa; saa += o.saa; sau += o.sau; suu += o.suu;
    sv += o.sv; sb += o.sb; sbb += o.sbb; sbv += o.sbv; svv += o.svv;
  }
  /// Throws InvalidInputError (naming `what`) when the fit is impossible or poor.
  PinholeCamera solve(int width, int height, const std::string& what) const;
};

void requireOrganized(std::uint32_t width, std::uint32_t height, const std::string& what);

} // namespace detail

template <typename PointT>
PinholeCamera estimatePinholeCamera(const pcl::PointCloud<PointT>& cloud) {
  detail::requireOrganized(cloud.width, cloud.height, "cloud");
  detail::PinholeFit fit;
  for (int v = 0; v < static_cast<int>(cloud.height); ++v)
    for (int u = 0; u < static_cast<int>(cloud.width); ++u) {
      const PointT& p = cloud[static_cast<std::size_t>(v) * cloud.width + u];
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.z > 0.f)
        fit.add(u, v, p.x, p.y, p.z);
    }
  return fit.solve(static_cast<int>(cloud.width), static_cast<int>(cloud.height), "cloud");
}

template <typename PointT>
DepthFrame toDepthFrame(const pcl::PointCloud<PointT>& cloud, const PinholeCamera* camera) {
  detail::requireOrganized(cloud.width, cloud.height, "cloud");
  DepthFrame frame;
  frame.camera = camera ? *camera : estimatePinholeCamera(cloud);
  const int rows = static_cast<int>(cloud.height), cols = static_cast<int>(cloud.width);
  frame.depth.create(rows, cols, CV_32FC1);
  constexpr bool kHasRgb = pcl::traits::has_field<PointT, pcl::fields::rgb>::value ||
                           pcl::traits::has_field<PointT, pcl::fields::rgba>::value;
  constexpr bool kHasWeight = pcl::traits::has_field<PointT, pcl::fields::weight>::value;
  if constexpr (kHasRgb)
    frame.color.create(rows, cols, CV_8UC3);
  if constexpr (kHasWeight)
    frame.weight.create(rows, cols, CV_32FC1);
#pragma omp parallel for
  for (int v = 0; v < rows; ++v) {
    const PointT* in = &cloud[static_cast<std::size_t>(v) * cols];
    float* depth = frame.depth.ptr<float>(v);
    for (int u = 0; u < cols; ++u) {
      const PointT& p = in[u];
      depth[u] = (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.z > 0.f) ? p.z : 0.f;
      if constexpr (kHasRgb) {
        std::uint8_t* bgr = frame.color.ptr<std::uint8_t>(v) + 3 * u;
        bgr[0] = p.b;
        bgr[1] = p.g;
        bgr[2] = p.r;
      }
      if constexpr (kHasWeight) {
        using WeightT = typename pcl::traits::datatype<PointT, pcl::fields::weight>::type;
        const float w = static_cast<float>(*reinterpret_cast<const WeightT*>(
            reinterpret_cast<const std::uint8_t*>(&p) + pcl::traits::offset<PointT, pcl::fields::weight>::value));
        frame.weight.ptr<float>(v)[u] = std::isfinite(w) && w > 0.f ? w : 0.f;
      }
    }
  }
  frame.validate();
  return frame;
}

} // namespace msf
