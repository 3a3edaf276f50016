#pragma once
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

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

} // namespace msf

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointXYZID,
                                  (float, x, x)(float, y, y)(float, z, z)(float, intensity, intensity)(float, distance, distance))
