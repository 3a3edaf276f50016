// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

namespace msf {

/// Section `map_prior`: the map rendered into the current view where the frame's own depth
/// has none (MapRaycaster).
struct MapPriorConfig {
  static constexpr const char* kSection = "map_prior";
  static constexpr const char* kAbout =
      "the map that earlier frames built, rendered into the view: the depth of the pixels the frame's fusion left "
      "without one (not integrated again)";
  /// Off by default: the rays of a frame's holes (on KITTI, tens of thousands of pixels above the
  /// LiDAR that stereo left empty, most marching the whole range) cost the map's thread more than
  /// the fill gains on KITTI's held-out rings (docs/results.md, "The map as a prior").
  bool enabled = false;
  /// A surface is taken only between voxels this well known (marching cubes' min_weight: what the mesh shows).
  float min_weight = 4.f;
  double min_depth_m = 1.0;
  double max_depth_m = 40.0;

  template <class Keys>
  void keys(Keys& k) {
    k("enabled", enabled, "fill the fused depth's holes with the map's surface seen from the frame's pose");
    k("min_weight", min_weight, atLeast(0), "voxels of this weight or less hold no surface for the prior, m^-2");
    k("min_depth_m", min_depth_m, atLeast(0), "rays start at this depth, m");
    k("max_depth_m", max_depth_m, Range{0, 1000.0, true, false}, "rays end at this depth, m");
  }
  /// Throws ConfigError naming the first key out of range.
  void validate() const;
};

/// Renders a TsdfVolume into a camera, as KinectFusion's raycast: along each pixel's ray, the
/// first crossing of the signed distance from positive to negative between observed voxels
/// (weight > min_weight), refined by trilinear interpolation. Rays step by the distance the
/// voxels say is free (at least a voxel), by a voxel through unobserved ones, and across a
/// block that is not allocated, or a sub-block without a voxel behind a surface
/// (TsdfBlock::negative_subblocks), in one step.
///
///   msf::MapRaycaster raycaster(volume, config.map_prior);
///   raycaster.render(camera, T_world_cam, holes, depth, weight);  // depth along the optical axis
///
/// Reads the volume only: const, safe beside other readers.
class MapRaycaster {
public:
  MapRaycaster(const TsdfVolume& volume, const MapPriorConfig& config);

  /// At each pixel where `mask` (CV_8UC1 of the camera's size) is non-zero: the depth along the
  /// optical axis of the map's first surface and its weight (the smaller of the voxel weights
  /// around the crossing, m^-2), 0 and 0 where the ray meets none; elsewhere 0. Throws
  /// InvalidInputError for a mask of another size or type, an invalid camera or a pose that is
  /// not rigid.
  void render(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, const cv::Mat& mask, cv::Mat& depth,
              cv::Mat& weight) const;

  /// The distance along the unit ray `direction` from `origin` (world, metres) to the first
  /// surface within [t_near, t_far], and its weight; false when it meets none.
  bool castRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_near, float t_far, float& t,
               float& weight) const;

private:
  const TsdfVolume& volume_;
  MapPriorConfig config_;
};

} // namespace msf
