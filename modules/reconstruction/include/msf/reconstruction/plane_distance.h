// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// Settings of planeDistanceScale: the `plane_` keys of section `tsdf_integrator`.
struct PlaneDistanceConfig {
  int step_px = 2;
  float max_curvature = 0.05f;
  /// The road is at s = h / z (camera height h): 0.05 keeps one voxel below it to ~33 m on
  /// KITTI, where 0.1 stops at ~16 m.
  float min_scale = 0.05f;

  template <class Keys>
  void keys(Keys& k) {
    k("plane_step_px", step_px, between(1, 64),
      "neighbours at +-this give the local plane of a pixel (a wider base averages stereo noise), px");
    k("plane_max_curvature", max_curvature, atLeast(0),
      "a pixel is on an edge where the second difference of 1/z over 1/z exceeds this");
    k("plane_min_scale", min_scale, Range{0, 1, true, false},
      "floor of the plane distance's scale, which bounds the band along a ray to truncation_m / this");
  }
};

/// Per pixel of a depth image, the factor s that turns the projective distance d - z of a
/// point on the pixel's ray (observed depth d, point depth z, both along the optical axis)
/// into its distance to the tangent plane of the observed surface: (d - z) * s.
///
/// On a plane n.P = c seen through the ray r = ((u - cx) / fx, (v - cy) / fy, 1), the inverse
/// depth is affine in the normalized image coordinates, 1/z = g.r with g = n / c, so the
/// distance from z r to the plane is |n.(d r - z r)| = (d - z) |n.r| = (d - z) / (d |g|):
/// s = 1 / (d |g|), from central differences of 1/z. s = 1 facing the camera and small at a
/// grazing angle (the road 20 m ahead of KITTI's camera: 0.08), where a band of +-truncation
/// along the ray is only a few centimetres high and marching cubes finds no sign change.
/// Next to an edge or a fold (the second difference of 1/z, relative to 1/z, exceeds
/// max_curvature) the slope along that axis is the one-sided difference of the side whose own
/// samples lie on a line; where neither does, or neighbours are missing, s = 1, the projective
/// distance.
/// s is at least min_scale, which bounds the band along the ray to truncation / min_scale.
///
/// depth: CV_32FC1 metres (not > 0 = none). Writes `scale` (CV_32FC1, same size, 1 where
/// there is no depth), reusing its buffer. Rows run in parallel.
void planeDistanceScale(const cv::Mat& depth, const PinholeCamera& camera, const PlaneDistanceConfig& config,
                        cv::Mat& scale);

/// Per pixel of a depth image, how much deeper than the pixel the smooth surface it lies on
/// is seen to go (metres): the largest depth of its run along its row and of its run along its
/// column, a run ending where 1/z bends by more than `max_curvature` of itself between three
/// consecutive pixels (an edge or a fold) or where there is no depth. A plane's distance holds
/// only where the plane goes on: behind the far edge of a car's roof seen at eye level it is
/// free space. 0 where there is no depth. Writes `extent` (CV_32FC1), reusing its buffer.
void smoothSurfaceExtent(const cv::Mat& depth, float max_curvature, cv::Mat& extent);

} // namespace msf
