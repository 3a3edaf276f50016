#pragma once
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cstdint>

namespace msf {

/// A point of a fused depth image: position in the rectified frame of camera 0, colour, and
/// `weight` in [0, 1], the confidence of its depth (DepthFusion documents it per method),
/// which a TSDF integrator can use as the per-pixel weight; 0 where there is no depth.
/// Registered, so .pcd files keep the field names and pcl_viewer still colours by `rgb`.
struct EIGEN_ALIGN16 PointXYZRGBWeight {
  PCL_ADD_POINT4D;
  PCL_ADD_RGB;
  float weight;

  inline PointXYZRGBWeight() : PointXYZRGBWeight(0.f, 0.f, 0.f) {}
  inline PointXYZRGBWeight(float x_, float y_, float z_, std::uint8_t r_ = 0, std::uint8_t g_ = 0,
                           std::uint8_t b_ = 0, float weight_ = 0.f)
      : weight(weight_) {
    x = x_;
    y = y_;
    z = z_;
    data[3] = 1.0f;
    r = r_;
    g = g_;
    b = b_;
    a = 255;
  }
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

} // namespace msf

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZRGBWeight,
                                  (float, x, x)(float, y, y)(float, z, z)(float, rgb, rgb)(float, weight, weight))
