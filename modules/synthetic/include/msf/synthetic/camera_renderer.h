// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/synthetic/scene_snapshot.h>
#include <msf/synthetic/synthetic_config.h>

#include <opencv2/core/mat.hpp>

#include <cstdint>

namespace msf::synthetic {

/// Renders the rectified cameras of a calibration by ray casting the scene: Lambertian
/// surfaces under a fixed sun and sky light (view independent, so the stereo pair agrees),
/// a gamma curve, Gaussian noise and 8-bit quantization. Anti-aliasing: one ray through
/// each pixel centre whose texture is filtered over the pixel's footprint on the surface
/// (ray differentials; stripes are box-filtered exactly, noise octaves finer than the
/// footprint fade out), and `supersampling` x `supersampling` rays in the pixels on a
/// geometric edge (where a neighbour sees another surface). Rows run in parallel; every
/// random value comes from a counter-based hash, so the result does not depend on
/// scheduling.
class CameraRenderer {
public:
  CameraRenderer(const Calibration& calibration, const SyntheticConfig& config);

  /// Image of camera 0..3 with camera 0 at T_world_cam0, seeing `scene` at its time: CV_8UC1 for the grey cameras
  /// 0 and 1, BGR CV_8UC3 for the colour cameras 2 and 3. `noise_key` selects the noise
  /// (use the frame index). When given, `depth` and `objects` receive the exact ground
  /// truth of the ray through each pixel centre: depth z in metres in this camera's frame
  /// (CV_32F, 0 where the sky is seen) and the foreground object id (CV_32S, 0 background).
  cv::Mat render(const SceneSnapshot& scene, int camera, const Eigen::Isometry3d& T_world_cam0, std::uint64_t noise_key,
                 cv::Mat* depth = nullptr, cv::Mat* objects = nullptr) const;

private:
  Calibration calibration_;
  SyntheticConfig config_;
};

} // namespace msf::synthetic
