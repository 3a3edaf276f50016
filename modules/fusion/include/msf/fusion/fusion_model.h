#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/io/calibration.h>

#include <opencv2/core/mat.hpp>

#include <algorithm>
#include <cmath>

namespace msf {

/// The two samples of one pixel and their cues. A depth is valid when > 0 and finite.
struct FusionInputs {
  float z_lidar = 0.f;           ///< interpolated LiDAR depth, metres
  float lidar_distance = 0.f;    ///< pixels from this pixel to the nearest real LiDAR return
  float lidar_range_px = 0.f;    ///< max - min LiDAR disparity around the pixel (uncertainty only)
  float z_stereo = 0.f;          ///< stereo depth, metres
  float stereo_confidence = 1.f; ///< in [0, 1], stereo_confidence.h
};

/// Fused depth (0 = none) and its weight in [0, 1] (0 = none).
struct FusionResult {
  float z = 0.f;
  float weight = 0.f;
};

namespace detail {
inline bool validDepth(float z) { return z > 0.f && std::isfinite(z); }
} // namespace detail

/// The paper's eq. 6 (DESIGN.md step 4), y = (y1 w1 + y2 w2 w1) / (w1 + w2 w1), with
/// y1 the stereo depth, y2 the LiDAR depth and the dynamic weights
///   w_L = paper_lidar_gain / (1 + distance / paper_lidar_distance_px)   (0 without LiDAR)
///          trust in the LiDAR, halved paper_lidar_distance_px pixels from a real return;
///   w_S = max(confidence, paper_min_stereo_confidence) * min(1, (z_ref / z_stereo)^2)
///          trust in stereo: its confidence, and its depth error growing as z^2 beyond z_ref;
///   w2  = w_L / w_S, the LiDAR's weight relative to stereo's;
///   w1  = 1 where stereo has a depth, in particular where the LiDAR sample is invalid
///          (w2 = 0 there) so that the stereo depth is used unchanged.
/// Wherever w1 != 0 it cancels: y = (y1 + w2 y2) / (1 + w2), the mean of the two depths
/// weighted w_S : w_L. Where stereo has no depth (w1 = 0, eq. 6 is 0/0) the LiDAR depth is
/// used. weight = min(1, w_L + w_S).
inline FusionResult fusePaper(const FusionInputs& in, const DepthFusionConfig& c) {
  const bool lidar = detail::validDepth(in.z_lidar), stereo = detail::validDepth(in.z_stereo);
  const float w_L = lidar ? c.paper_lidar_gain / (1.f + in.lidar_distance / c.paper_lidar_distance_px) : 0.f;
  if (!stereo)
    return lidar ? FusionResult{in.z_lidar, std::min(1.f, w_L)} : FusionResult{};
  const float ratio = c.paper_stereo_reference_depth_m / in.z_stereo;
  const float w_S = std::max(in.stereo_confidence, c.paper_min_stereo_confidence) * std::min(1.f, ratio * ratio);
  const float w1 = 1.f;
  const float w2 = w_L / w_S;
  const float y1 = in.z_stereo, y2 = lidar ? in.z_lidar : 0.f;
  return {(y1 * w1 + y2 * w2 * w1) / (w1 + w2 * w1), std::min(1.f, w_L + w_S)};
}

/// Sigma of a stereo disparity (pixels): stereo_sigma_min_px at confidence 1, rising
/// quadratically in (1 - confidence) to stereo_sigma_max_px at confidence 0.
inline float stereoSigmaPx(float confidence, const DepthFusionConfig& c) {
  const float u = 1.f - std::clamp(confidence, 0.f, 1.f);
  return c.stereo_sigma_min_px + (c.stereo_sigma_max_px - c.stereo_sigma_min_px) * u * u;
}

/// Sigma of an interpolated LiDAR disparity (pixels): lidar_sigma_px on a real return on a
/// smooth surface, growing linearly with the distance to the nearest real return and with
/// the local disparity range (across an object edge interpolation mixes the two sides, and
/// a return from behind a foreground edge, which the LiDAR mounted above the camera sees
/// and the camera does not, sits next to the foreground's returns).
inline float lidarSigmaPx(float distance, float range_px, const DepthFusionConfig& c) {
  return c.lidar_sigma_px + c.lidar_sigma_per_distance * distance + c.lidar_sigma_per_range * range_px;
}

/// True when the LiDAR sample of a pixel is likely a return from behind a foreground edge:
/// the LiDAR, mounted `lidar_height_m` above the camera, sees over the top edge of a near
/// object onto the background, and such returns land in the camera image up to
/// f * h * (1/z_near - 1/z_far) = (h / B) * (d_near - d_far) rows below the edge, inside the
/// object. The evidence: stereo sees a nearer surface here (disparity d_stereo > d_lidar),
/// and the LiDAR itself has that nearer surface within that many rows below the pixel.
/// `lidar_below(k)` returns the LiDAR depth k rows below (0 = none or outside the image);
/// `rows_per_px` = h / B. At most `max_rows` rows are read.
template <typename LidarBelow>
inline bool lidarSeesPastForeground(float d_lidar, float d_stereo, float tolerance_px, float focal_baseline,
                                    float rows_per_px, int max_rows, LidarBelow&& lidar_below) {
  if (!(rows_per_px > 0.f) || d_stereo <= d_lidar)
    return false;
  const int rows = std::min(max_rows, static_cast<int>(std::ceil(rows_per_px * (d_stereo - d_lidar))) + 1);
  for (int k = 1; k <= rows; ++k) {
    const float z = lidar_below(k);
    if (z > 0.f && focal_baseline / z >= d_stereo - tolerance_px)
      return true;
  }
  return false;
}

/// Parallax geometry of the LiDAR over the camera for lidarSeesPastForeground.
struct LidarParallax {
  float rows_per_px = 0.f; ///< lidar height above the camera / stereo baseline (0: no check)
  int max_rows = 0;        ///< rows read at most
};

/// Inverse-variance fusion in disparity d = f B / z, where both sensors' errors are
/// measured: stereo sigma_z = z^2 sigma_d / (f B) is sigma_d in disparity, and the LiDAR's
/// interpolation error is a few tenths of a pixel there. Two samples further apart than
/// disagreement_k_sigma * sqrt(sigma_L^2 + sigma_S^2) are not averaged (that would put a
/// point between foreground and background): the one with the smaller sigma is kept, except
/// that stereo wins where the LiDAR sample was seen past a foreground edge
/// (lidarSeesPastForeground; `lidar_below` reads the LiDAR depth image below the pixel).
/// weight = min(1, (stereo_sigma_min_px / sigma)^2), 1 for a stereo match of confidence 1.
template <typename LidarBelow>
inline FusionResult fuseUncertainty(const FusionInputs& in, const DepthFusionConfig& c, float focal_baseline,
                                    const LidarParallax& parallax, LidarBelow&& lidar_below) {
  const bool lidar = detail::validDepth(in.z_lidar), stereo = detail::validDepth(in.z_stereo);
  if (!lidar && !stereo)
    return {};
  const auto weightOf = [&](float sigma) {
    const float r = c.stereo_sigma_min_px / sigma;
    return std::min(1.f, r * r);
  };
  const float s_L = lidar ? lidarSigmaPx(in.lidar_distance, in.lidar_range_px, c) : 0.f;
  const float s_S = stereo ? stereoSigmaPx(in.stereo_confidence, c) : 0.f;
  if (!stereo)
    return {in.z_lidar, weightOf(s_L)};
  if (!lidar)
    return {in.z_stereo, weightOf(s_S)};
  const float d_L = focal_baseline / in.z_lidar, d_S = focal_baseline / in.z_stereo;
  const float v_L = s_L * s_L, v_S = s_S * s_S;
  const float diff = d_L - d_S, k = c.disagreement_k_sigma;
  if (diff * diff > k * k * (v_L + v_S)) {
    const bool stereo_wins =
        s_S < s_L || lidarSeesPastForeground(d_L, d_S, k * s_S, focal_baseline, parallax.rows_per_px,
                                             parallax.max_rows, lidar_below);
    return stereo_wins ? FusionResult{in.z_stereo, weightOf(s_S)} : FusionResult{in.z_lidar, weightOf(s_L)};
  }
  const float d = (d_L * v_S + d_S * v_L) / (v_L + v_S);
  return {focal_baseline / d, weightOf(std::sqrt(v_L * v_S / (v_L + v_S)))};
}

/// Without the image below the pixel: no parallax check.
inline FusionResult fuseUncertainty(const FusionInputs& in, const DepthFusionConfig& c, float focal_baseline) {
  return fuseUncertainty(in, c, focal_baseline, LidarParallax{}, [](int) { return 0.f; });
}

/// Both methods of `c.method`.
template <typename LidarBelow>
inline FusionResult fusePixel(const FusionInputs& in, const DepthFusionConfig& c, float focal_baseline,
                              const LidarParallax& parallax, LidarBelow&& lidar_below) {
  return c.method == FusionMethod::Paper ? fusePaper(in, c)
                                         : fuseUncertainty(in, c, focal_baseline, parallax, lidar_below);
}

/// The parallax of `calibration`'s LiDAR over camera 0 (none when the LiDAR is not above it),
/// with config.parallax_check.
LidarParallax lidarParallax(const Calibration& calibration, const DepthFusionConfig& config);

/// Local disparity range of a depth image (CV_32F metres, 0 = none): at each pixel, the
/// largest minus the smallest disparity f B / z over the valid pixels of the odd `window`
/// (0 where the window holds at most one value). Reuses `range` when it has the right size.
/// Throws InvalidInputError for a wrong type.
void localDisparityRange(const cv::Mat& depth, double focal_baseline, int window, cv::Mat& range);

} // namespace msf
