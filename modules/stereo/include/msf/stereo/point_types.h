#pragma once
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cstdint>

namespace msf {

/// A point of a stereo depth image: position in the rectified frame of camera 0, colour
/// from the colour camera, and `confidence` in [0, 1] of its disparity (see
/// stereo_confidence.h; 0 where there is no depth). Fusion scales the stereo disparity
/// noise by 1 / confidence. Registered, so .pcd files keep the field names for chaining
/// msf_stereo -> msf_fuse, and pcl_viewer still colours the cloud by `rgb`.
struct EIGEN_ALIGN16 PointXYZRGBConfidence {
  PCL_ADD_POINT4D;
  PCL_ADD_RGB;
  float confidence;

  inline PointXYZRGBConfidence() : PointXYZRGBConfidence(0.f, 0.f, 0.f) {}
  inline PointXYZRGBConfidence(float x_, float y_, float z_, std::uint8_t r_ = 0, std::uint8_t g_ = 0,
                               std::uint8_t b_ = 0, float confidence_ = 0.f)
      : confidence(confidence_) {
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

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZRGBConfidence,
                                  (float, x, x)(float, y, y)(float, z, z)(float, rgb, rgb)(float, confidence, confidence))
