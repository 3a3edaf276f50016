// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/plane_distance.h>

#include <opencv2/core/mat.hpp>

#include <memory>

namespace msf {

/// What a voxel's signed distance measures in TsdfIntegrator. A voxel at depth z on the ray of
/// a pixel whose depth is d has the signed distance (d - z) s, s the pixel's scale; behind the
/// surface its band reaches no deeper than the pixel's extent, how far the surface is seen to
/// go on. Chosen by the config's `tsdf_integrator.signed_distance` (makeSignedDistance) or
/// given to the integrator (TsdfIntegrator::setSignedDistance).
class SignedDistanceModel {
public:
  using ConstPtr = std::shared_ptr<const SignedDistanceModel>;
  virtual ~SignedDistanceModel() = default;
  /// Per pixel of `depth` (CV_32FC1, metres), its scale and extent (CV_32FC1 of its size),
  /// reusing the buffers.
  virtual void pixelScales(const cv::Mat& depth, const PinholeCamera& camera, cv::Mat& scale,
                           cv::Mat& extent) const = 0;
  /// The deepest a band of `plane_band` metres across the surface reaches behind it along a
  /// ray (bounds TsdfIntegrator::reach).
  virtual double widestBandBelow(double plane_band) const = 0;
};

/// Depth difference along the optical axis (KinectFusion, the paper): scale 1, and nothing
/// beyond the truncation behind the surface.
class ProjectiveDistance : public SignedDistanceModel {
public:
  void pixelScales(const cv::Mat& depth, const PinholeCamera& camera, cv::Mat& scale, cv::Mat& extent) const override;
  double widestBandBelow(double) const override { return 0.0; }
};

/// Distance to the observed surface's tangent plane (planeDistanceScale), the band behind it
/// bounded by how far the smooth surface is seen (smoothSurfaceExtent).
class PlaneDistance : public SignedDistanceModel {
public:
  explicit PlaneDistance(const PlaneDistanceConfig& config) : config_(config) {}
  void pixelScales(const cv::Mat& depth, const PinholeCamera& camera, cv::Mat& scale, cv::Mat& extent) const override;
  double widestBandBelow(double plane_band) const override {
    return plane_band / static_cast<double>(config_.min_scale);
  }

private:
  PlaneDistanceConfig config_;
};

} // namespace msf
