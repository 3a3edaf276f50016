// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

namespace msf {

/// One observed voxel of a TsdfVolume as a point: its centre (x y z, metres), sdf (metres),
/// weight, colour (rgb), passes and reappeared (TsdfVoxel's, 0 or 1). A .pcd of these is the
/// volume on disk (TsdfVolume::save), so tools chain and pcl_viewer shows it (coloured by rgb,
/// or by the sdf field). A default point is an unobserved voxel at the origin: every field 0,
/// black and opaque, as PCL's own point types start.
struct EIGEN_ALIGN16 PointTsdf {
  PCL_ADD_POINT4D;
  float sdf;
  float weight;
  PCL_ADD_RGB;
  std::uint8_t passes;
  std::uint8_t reappeared;

  inline PointTsdf() : sdf(0.f), weight(0.f), passes(0), reappeared(0) {
    x = y = z = 0.f;
    data[3] = 1.0f;
    rgba = std::uint32_t{255} << 24;
  }
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

} // namespace msf

POINT_CLOUD_REGISTER_POINT_STRUCT(msf::PointTsdf,
                                  (float, x, x)(float, y, y)(float, z, z)(float, sdf, sdf)(float, weight, weight)(
                                      float, rgb, rgb)(std::uint8_t, passes, passes)(
                                      std::uint8_t, reappeared, reappeared))
