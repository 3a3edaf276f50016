// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/io/calibration.h>

#include <opencv2/core/mat.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace msf {

/// The two samples of one pixel and their cues. A depth is valid when > 0 and finite.
struct FusionInputs {
  float z_lidar = 0.f;           ///< interpolated LiDAR depth, metres
  float lidar_distance = 0.f;    ///< pixels from this pixel to the nearest real LiDAR return
  float lidar_edge_px = 0.f;     ///< the LiDAR's edge cue at the pixel, lidarEdgeCue (uncertainty only)
  float z_stereo = 0.f;          ///< stereo depth, metres
  float stereo_confidence = 1.f; ///< in [0, 1], stereo_confidence.h
};

/// Fused depth (0 = none) and its weight (0 = none): fusePaper's in [0, 1], fuseUncertainty's
/// the inverse variance of the depth in m^-2 (depthWeight). fuseRow gives both methods' in
/// m^-2, what the integrator averages with. free_weight: the weight of the evidence that the
/// ray is free in front of the depth; the weight's, except for an average of two samples
/// that disagree (fuseUncertainty): its depth is uncertain, the space in front of both is not.
struct FusionResult {
  float z = 0.f;
  float weight = 0.f;
  float free_weight = 0.f;
};

namespace detail {
inline bool validDepth(float z) { return z > 0.f && std::isfinite(z); }
} // namespace detail

// The per-pixel functions below are written with selects rather than branches, so that the
// row loops (fuseRow) vectorise. A depth that is not > 0 (0, negative, NaN) is none.

/// The paper's eq. 6 (docs/design.md, step 4), y = (y1 w1 + y2 w2 w1) / (w1 + w2 w1), with
/// y1 the stereo depth, y2 the LiDAR depth and the dynamic weights
///   w_L = paper_lidar_gain / (1 + distance / paper_lidar_distance_px)   (0 without LiDAR)
///          trust in the LiDAR, halved paper_lidar_distance_px pixels from a real return;
///   w_S = max(confidence, paper_min_stereo_confidence) * min(1, (z_ref / z_stereo)^2)
///          trust in stereo: its confidence, and its depth error growing as z^2 beyond z_ref.
/// paper_weights picks what eq. 6 multiplies:
///   as_written: w1 = w_S, the stereo weight (1 where the LiDAR sample is invalid, so that the
///          stereo depth is used unchanged there), and w2 = w_L. Wherever w1 != 0 it cancels:
///          y = (y1 + w_L y2) / (1 + w_L), so stereo's confidence never moves the depth;
///   relative (the project's reading): w1 = 1 and w2 = w_L / w_S, the LiDAR's weight relative
///          to stereo's, so that y is the mean of the two depths weighted w_S : w_L.
/// Where stereo has no depth (w1 = 0, eq. 6 is 0/0) the LiDAR depth is used.
/// weight = min(1, w_L + w_S).
inline FusionResult fusePaper(const FusionInputs& in, const DepthFusionConfig& c) {
  const bool lidar = in.z_lidar > 0.f, stereo = in.z_stereo > 0.f;
  const float w_L_any = c.paper_lidar_gain / (1.f + in.lidar_distance / c.paper_lidar_distance_px);
  const float w_L = lidar ? w_L_any : 0.f;
  const float ratio = c.paper_stereo_reference_depth_m / (stereo ? in.z_stereo : 1.f);
  const float w_S = std::max(in.stereo_confidence, c.paper_min_stereo_confidence) * std::min(1.f, ratio * ratio);
  const bool as_written = c.paper_weights == PaperWeights::AsWritten;
  const float w1 = as_written && lidar ? w_S : 1.f; // > 0 wherever stereo has a depth
  const float w2 = as_written ? w_L : w_L / w_S;
  const float y1 = in.z_stereo, y2 = lidar ? in.z_lidar : 0.f;
  const float y = (y1 * w1 + y2 * w2 * w1) / (w1 + w2 * w1);
  FusionResult r;
  r.z = stereo ? y : (lidar ? in.z_lidar : 0.f);
  r.weight = std::min(1.f, stereo ? w_L + w_S : w_L);
  r.free_weight = r.weight;
  return r;
}

/// Sigma of a stereo disparity (pixels): stereo_sigma_min_px at confidence 1, rising
/// quadratically in (1 - confidence) to stereo_sigma_max_px at confidence 0.
inline float stereoSigmaPx(float confidence, const DepthFusionConfig& c) {
  const float u = 1.f - std::clamp(confidence, 0.f, 1.f);
  return c.stereo_sigma_min_px + (c.stereo_sigma_max_px - c.stereo_sigma_min_px) * u * u;
}

/// Sigma of an interpolated LiDAR disparity (pixels): lidar_sigma_px on a real return on a
/// smooth surface, growing linearly with the distance to the nearest real return and with
/// the edge cue (lidarEdgeCue: across an object edge interpolation mixes the two sides, and
/// a return from behind a foreground edge, which the LiDAR mounted above the camera sees
/// and the camera does not, sits next to the foreground's returns).
inline float lidarSigmaPx(float distance, float edge_px, const DepthFusionConfig& c) {
  return c.lidar_sigma_px + c.lidar_sigma_per_distance * distance + c.lidar_sigma_per_range * edge_px;
}

/// The inverse variance of a depth z, 1 / sigma_z^2 in m^-2, from the inverse variance of its
/// disparity `inverse_variance_px` (1 / sigma_d^2, px^-2): sigma_z = z^2 sigma_d / (f B), the
/// error of stereo. 0 for no depth. The best stereo match (0.35 px) on KITTI weighs ~120 at
/// 10 m (sigma 0.09 m) and ~7.7 at 20 m (0.36 m): what the TSDF integrator averages with.
inline float depthWeight(float z, float inverse_variance_px, float focal_baseline) {
  const float z_safe = z > 0.f ? z : 1.f;
  const float k = focal_baseline / (z_safe * z_safe);
  return z > 0.f ? k * k * inverse_variance_px : 0.f;
}

/// The inverse variance (m^-2) of an interpolated LiDAR depth z whose interpolation error is
/// `interpolation_px` in disparity: the range noise of a return, lidar_range_sigma_m, whatever
/// the depth, and that error in depth (z^2 / (f B) per pixel). A real return weighs
/// 1 / lidar_range_sigma_m^2 at 5 m as at 40 m. 0 for no depth.
inline float lidarDepthWeight(float z, float interpolation_px, float focal_baseline, const DepthFusionConfig& c) {
  const float z_safe = z > 0.f ? z : 1.f;
  const float interpolation = z_safe * z_safe * interpolation_px / focal_baseline;
  const float variance = c.lidar_range_sigma_m * c.lidar_range_sigma_m + interpolation * interpolation;
  return z > 0.f ? 1.f / variance : 0.f;
}

/// Inverse-variance fusion in disparity d = f B / z, where both sensors' errors are
/// measured: stereo sigma_z = z^2 sigma_d / (f B) is sigma_d in disparity, and the LiDAR's
/// interpolation error is a few tenths of a pixel there. Two samples further apart than
/// disagreement_k_sigma * sqrt(sigma_L^2 + sigma_S^2) are not averaged (that would put a
/// point between foreground and background): the one with the smaller sigma is kept. When
/// that is the LiDAR while stereo sees a nearer surface (z = z_lidar > z_stereo > 0),
/// fuseRow checks lidarSeesPastForeground, and then stereo wins.
/// weight: the inverse variance of the result's depth, lidarDepthWeight or the stereo's
/// depthWeight, or their sum where both are averaged.
inline FusionResult fuseUncertainty(const FusionInputs& in, const DepthFusionConfig& c, float focal_baseline) {
  // Bitwise & and | on the flags, and every division done unconditionally: no branches.
  const bool lidar = in.z_lidar > 0.f, stereo = in.z_stereo > 0.f;
  const float s_L = lidarSigmaPx(in.lidar_distance, in.lidar_edge_px, c);
  const float s_S = stereoSigmaPx(in.stereo_confidence, c);
  const float v_L = s_L * s_L, v_S = s_S * s_S, v_sum = v_L + v_S;
  const float d_L = focal_baseline / (lidar ? in.z_lidar : 1.f);
  const float d_S = focal_baseline / (stereo ? in.z_stereo : 1.f);
  const float diff = d_L - d_S, k = c.disagreement_k_sigma;
  const bool both = lidar & stereo;
  const bool agree = diff * diff <= k * k * v_sum;
  const bool lidar_more_certain = s_L <= s_S;
  // Where both agree: the inverse-variance mean, of variance v_L v_S / (v_L + v_S).
  const float z_mean = focal_baseline * v_sum / (d_L * v_S + d_S * v_L);
  const bool no_lidar = !lidar, no_stereo = !stereo, disagree = !agree, stereo_more_certain = !lidar_more_certain;
  const bool take_lidar = lidar & (no_stereo | (disagree & lidar_more_certain));
  const bool take_stereo = stereo & (no_lidar | (disagree & stereo_more_certain));
  // The LiDAR's weight counts its error growing away from a return, not lidarSigmaPx's term of
  // the local disparity range: on the road that is a plane's slope (a third of a pixel a row
  // on KITTI), and as a weight it left the far road unmeshed. At edges the fusion itself
  // decides (parallax check, edge support).
  const float w_L = lidarDepthWeight(in.z_lidar, c.lidar_sigma_per_distance * in.lidar_distance, focal_baseline, c);
  const float w_S = depthWeight(in.z_stereo, 1.f / v_S, focal_baseline);
  // An average's variance is its samples' spread about it as well as theirs: where the two
  // disagree (a LiDAR return seen past a pole that stereo sees), the mean lies between two
  // surfaces and must not weigh as a LiDAR return.
  const float w_sum = both ? w_L + w_S : 1.f;
  const float dz_L = in.z_lidar - z_mean, dz_S = in.z_stereo - z_mean;
  const float spread = (w_L * dz_L * dz_L + w_S * dz_S * dz_S) / w_sum;
  const float w_mean = 1.f / (1.f / w_sum + spread);
  FusionResult r;
  r.z = take_lidar ? in.z_lidar : (take_stereo ? in.z_stereo : (both ? z_mean : 0.f));
  r.weight = take_lidar ? w_L : (take_stereo ? w_S : (both ? w_mean : 0.f));
  r.free_weight = take_lidar ? w_L : (take_stereo ? w_S : (both ? w_L + w_S : 0.f));
  return r;
}

/// True when the LiDAR sample of a pixel is likely a return from behind a foreground edge:
/// the LiDAR, mounted a height h above the camera, sees over the top edge of a near object
/// onto the background, and such returns land in the camera image up to
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

/// The parallax of `calibration`'s LiDAR over camera 0 (none when the LiDAR is not above it),
/// with config.parallax_check.
LidarParallax lidarParallax(const Calibration& calibration, const DepthFusionConfig& config);

/// One image row of the fusion, the loop both DepthFusion and DepthImageFusion run: `width`
/// pixels of row `v` of `lidar_depth` (CV_32FC1, not > 0 = none), with the row's LiDAR
/// distances and edge cue (lidarEdgeCue; read by the uncertainty method only), stereo depths
/// (not > 0 = none) and confidences; no pointer may be null. Writes fused depth (0 = none),
/// weight and free-space weight (FusionResult). The per-pixel pass
/// vectorises; the rare parallax checks follow it.
void fuseRow(const DepthFusionConfig& c, float focal_baseline, const LidarParallax& parallax,
             const cv::Mat& lidar_depth, int v, const float* __restrict__ lidar_distance,
             const float* __restrict__ lidar_edge, const float* __restrict__ z_stereo,
             const float* __restrict__ stereo_confidence, float* __restrict__ fused_z,
             float* __restrict__ fused_weight, float* __restrict__ fused_free_weight);

/// Local disparity range of a depth image (CV_32F metres, 0 = none): at each pixel, the
/// largest minus the smallest disparity f B / z over the valid pixels of the odd `window`
/// (0 where the window holds at most one value). Reuses `range` when it has the right size.
/// Throws InvalidInputError for a wrong type or an even window.
void localDisparityRange(const cv::Mat& depth, double focal_baseline, int window, cv::Mat& range);

/// Local bend of a depth image's disparity d = f B / z (CV_32F metres, 0 = none): at each
/// valid pixel, the larger of |d(u - s) + d(u + s) - 2 d(u)| along the row and along the
/// column, s = step pixels (a side without both neighbours valid counts 0). On any plane d is
/// affine in the pixel coordinates and the bend is 0, however steep (the road); at an object's
/// edge it is the step's height. Reuses `bend` when it has the right size. Throws
/// InvalidInputError for a wrong type or a step < 1.
void localDisparityBend(const cv::Mat& depth, double focal_baseline, int step, cv::Mat& bend);

/// The LiDAR's edge cue for lidarSigmaPx, as config.lidar_edge_cue says: the local disparity
/// bend with step lidar_range_window_px / 2 (bend), or the local disparity range over the
/// window (range).
void lidarEdgeCue(const cv::Mat& lidar_depth, double focal_baseline, const DepthFusionConfig& config,
                  cv::Mat& cue);

} // namespace msf
