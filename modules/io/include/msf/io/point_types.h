// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The point types of the stages' organized clouds, registered with PCL (so .pcd files keep
// their field names and pcl_viewer opens them). Here, in the module every stage builds on, so
// that each stage's templates are instantiated for every one of them.
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cstdint>
#include <limits>

namespace msf {

/// A point of an interpolated LiDAR depth image: position in the camera's rectified frame,
/// reflectance, and `distance`, the distance in pixels from its pixel to the nearest real
/// LiDAR return (0 on a real return). Fusion uses `distance` to weigh the LiDAR estimate;
/// as a registered type, .pcd files keep the field names and pcl_viewer opens them.
struct EIGEN_ALIGN16 PointXYZID {
  PCL_ADD_POINT4D;
  float intensity;
  float distance;

  inline PointXYZID() : PointXYZID(0.f, 0.f, 0.f, 0.f, 0.f) {}
  inline PointXYZID(float x_, float y_, float z_, float intensity_ = 0.f, float distance_ = 0.f)
      : intensity(intensity_), distance(distance_) {
    x = x_;
    y = y_;
    z = z_;
    data[3] = 1.0f;
  }
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

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

/// A point of a fused depth image: position in the rectified frame of camera 0, colour, and
/// `weight`, the confidence of its depth (DepthFusion documents it per method), which a TSDF
/// integrator can use as the per-pixel weight; 0 where there is no depth. What the map takes
/// beside the depth: `free_space_weight`, the weight of the free space in front of it (the
/// fusion's differs from `weight` where it averaged two samples that disagree), and
/// `sky_depth`, NaN where the pixel is not open sky, else the depth up to which its ray passed
/// every surface (the LiDAR's highest return in its column; +inf in the clear sky, clipped or
/// blue, and where the column has none).
/// Registered, so .pcd files keep the field names and pcl_viewer still colours by `rgb`.
struct EIGEN_ALIGN16 PointXYZRGBWeight {
  PCL_ADD_POINT4D;
  PCL_ADD_RGB;
  float weight;
  float free_space_weight;
  float sky_depth;

  inline PointXYZRGBWeight() : PointXYZRGBWeight(0.f, 0.f, 0.f) {}
  inline PointXYZRGBWeight(float x_, float y_, float z_, std::uint8_t r_ = 0, std::uint8_t g_ = 0,
                           std::uint8_t b_ = 0, float weight_ = 0.f)
      : weight(weight_), free_space_weight(weight_), sky_depth(std::numeric_limits<float>::quiet_NaN()) {
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

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZID,
                                  (float, x, x)(float, y, y)(float, z, z)(float, intensity, intensity)(float, distance, distance))

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZRGBConfidence,
                                  (float, x, x)(float, y, y)(float, z, z)(float, rgb, rgb)(float, confidence, confidence))

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZRGBWeight,
                                  (float, x, x)(float, y, y)(float, z, z)(float, rgb, rgb)(float, weight, weight)(
                                      float, free_space_weight, free_space_weight)(float, sky_depth, sky_depth))
