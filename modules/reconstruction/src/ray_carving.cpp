// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/parallel.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include "surface_voxel_walk.h"
#include "voxel_update.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace msf {

namespace {

constexpr int kSide = TsdfBlock::kSide;
/// How far (pixels) a depth image's silhouettes may lie from the true ones: interpolation and
/// stereo matching both widen or narrow an object by a pixel or two.
constexpr float kSilhouetteSlackPx = 3.f;

/// The pixels that a block's bounding sphere (centre `c` in the camera frame, radius `r`) may
/// project into, with a pixel to spare, within the image; empty where it lies outside
/// [min_d, max_d] of depth.
cv::Rect sphereFootprint(const Eigen::Vector3f& c, float r, const PinholeCamera& cam, float min_d, float max_d) {
  if (c.z() + r < min_d || c.z() - r > max_d)
    return {};
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float z = std::max(c.z() - r, min_d); // the sphere's nearest depth: its widest footprint
  const float r_px = std::max(fx, fy) * r / z + 1.f;
  const float zc = std::max(c.z(), min_d);
  const float u = fx * c.x() / zc + static_cast<float>(cam.cx), v = fy * c.y() / zc + static_cast<float>(cam.cy);
  const cv::Rect image(0, 0, cam.width, cam.height);
  const float lo_u = std::max(u - r_px, -1.f), hi_u = std::min(u + r_px, static_cast<float>(cam.width));
  const float lo_v = std::max(v - r_px, -1.f), hi_v = std::min(v + r_px, static_cast<float>(cam.height));
  if (!(lo_u <= hi_u && lo_v <= hi_v))
    return {};
  const cv::Point first(static_cast<int>(std::floor(lo_u)), static_cast<int>(std::floor(lo_v)));
  const cv::Point last(static_cast<int>(std::ceil(hi_u)) + 1, static_cast<int>(std::ceil(hi_v)) + 1);
  return cv::Rect(first, last) & image;
}

/// A block test of carveAlongRays that keeps every block whose footprint holds a ray.
constexpr auto kAnyBlock = [](const cv::Rect&, float) { return true; };

/// Carves the voxels behind a surface (sdf < 0) whose centres project into a non-zero pixel of
/// `rays` (CV_8UC1 of `camera`'s size) within `rect` of it, from min_d to max_d of depth: a
/// free-space update of weight freeWeight(u, v, z) each (none where it is 0). Only the blocks
/// whose footprint holds such a pixel are walked, and of them those for which
/// mayCarve(footprint, farthest depth) holds: freeWeight is 0 at every pixel of a block it rules out.
template <class FreeWeight, class BlockTest>
void carveAlongRays(TsdfVolume& volume, const cv::Mat& rays, const cv::Rect& rect, const PinholeCamera& camera,
                    const Eigen::Isometry3d& T_world_cam, float min_d, float max_d, float max_weight,
                    FreeWeight&& freeWeight, BlockTest&& mayCarve) {
  const float vs = static_cast<float>(volume.voxelSize()), trunc = static_cast<float>(volume.truncation());
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  const float radius = 0.5f * std::sqrt(3.f) * kSide * vs;
  // The rays in a footprint are counted on their integral image.
  cv::Mat count;
  cv::integral(rays(rect) != 0, count, CV_32S);
  std::vector<TsdfBlock*> blocks;
  for (const auto& block : volume.blocks()) {
    if (!block->negative_subblocks)
      continue; // nothing behind a surface: nothing to carve
    const Eigen::Vector3f centre =
        T_cam_world * ((block->origin().cast<float>() + Eigen::Vector3f::Constant(3.5f)) * vs);
    const cv::Rect footprint = sphereFootprint(centre, radius, camera, min_d, max_d) & rect;
    if (footprint.empty())
      continue;
    const cv::Rect seen = footprint - rect.tl();
    const int bottom = seen.y + seen.height, right = seen.x + seen.width;
    if (count.at<int>(bottom, right) - count.at<int>(seen.y, right) - count.at<int>(bottom, seen.x) +
                count.at<int>(seen.y, seen.x) > 0 &&
        mayCarve(footprint, std::min(centre.z() + radius, max_d)))
      blocks.push_back(block);
  }
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const std::uint64_t stamp = volume.beginGeneration();
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n)
      detail::carveSurfaceVoxels(*blocks[static_cast<std::size_t>(n)], T_cam_world, vs, stamp,
                                 [&](TsdfVoxel& voxel, const Eigen::Vector3f& p) {
                                   if (p.z() < min_d || p.z() > max_d)
                                     return false;
                                   const int u = static_cast<int>(std::lround(fx * p.x() / p.z() + cx));
                                   const int v = static_cast<int>(std::lround(fy * p.y() / p.z() + cy));
                                   if (u < 0 || v < 0 || u >= camera.width || v >= camera.height ||
                                       !rays.at<std::uint8_t>(v, u))
                                     return false;
                                   const float w = freeWeight(u, v, p.z());
                                   if (!(w > 0.f))
                                     return false;
                                   detail::updateVoxel(voxel, trunc, w, nullptr, max_weight, trunc, true);
                                   return true;
                                 });
  });
}

constexpr int kDistanceTile = 16;

/// The largest value of each kDistanceTile-pixel square tile of `values` (CV_32FC1, >= 0).
void tileMaxima(const cv::Mat& values, cv::Mat& maxima) {
  maxima.create((values.rows + kDistanceTile - 1) / kDistanceTile, (values.cols + kDistanceTile - 1) / kDistanceTile,
                CV_32FC1);
  maxima.setTo(0.f);
  for (int v = 0; v < values.rows; ++v) {
    const float* row = values.ptr<float>(v);
    float* tiles = maxima.ptr<float>(v / kDistanceTile);
    for (int t = 0; t < maxima.cols; ++t)
      for (int u = t * kDistanceTile; u < std::min(values.cols, (t + 1) * kDistanceTile); ++u)
        tiles[t] = std::max(tiles[t], row[u]);
  }
}

/// The largest of `maxima`'s tiles that `rect` (pixels of the image they were taken of) overlaps:
/// no value within `rect` is larger.
float largestOver(const cv::Mat& maxima, const cv::Rect& rect) {
  float largest = 0.f;
  const int last_row = std::min(maxima.rows - 1, (rect.y + rect.height - 1) / kDistanceTile);
  const int last_col = std::min(maxima.cols - 1, (rect.x + rect.width - 1) / kDistanceTile);
  for (int r = rect.y / kDistanceTile; r <= last_row; ++r)
    for (int c = rect.x / kDistanceTile; c <= last_col; ++c)
      largest = std::max(largest, maxima.at<float>(r, c));
  return largest;
}

/// The pixels whose depth lies beyond `range` by more than `sigmas` of its sigma (1/sqrt of its
/// weight; `weight` may be empty: every depth is precise enough).
void raysBeyondRange(const cv::Mat& depth, const cv::Mat& weight, float range, float sigmas, cv::Mat& rays) {
  rays.create(depth.size(), CV_8UC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* d = depth.ptr<float>(v);
    const float* w = weight.empty() ? nullptr : weight.ptr<float>(v);
    std::uint8_t* out = rays.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      const float sigma = w ? (w[u] > 0.f ? 1.f / std::sqrt(w[u]) : std::numeric_limits<float>::infinity()) : 0.f;
      out[u] = d[u] - sigmas * sigma > range ? 255 : 0;
    }
  }
}

} // namespace

void TsdfIntegrator::checkSkyDepth(const cv::Mat& sky_depth, const PinholeCamera& camera) {
  if (sky_depth.type() != CV_32FC1 || sky_depth.cols != camera.width || sky_depth.rows != camera.height)
    throw InvalidInputError("the sky depth must be CV_32FC1 of the camera's " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + ", not " + std::to_string(sky_depth.cols) + "x" +
                            std::to_string(sky_depth.rows) + " " + cv::typeToString(sky_depth.type()));
  checkSkyDepthBounds(sky_depth, "the sky depth");
}

void TsdfIntegrator::carveSky(const cv::Mat& sky_depth, const PinholeCamera& camera,
                              const Eigen::Isometry3d& T_world_cam, float weight) {
  if (!carvesSky() || sky_depth.empty())
    return;
  checkSkyDepth(sky_depth, camera);
  carveCheckedSky(sky_depth, camera, T_world_cam, weight);
}

void TsdfIntegrator::carveCheckedSky(const cv::Mat& sky_depth, const PinholeCamera& camera,
                                     const Eigen::Isometry3d& T_world_cam, float weight) {
  if (!(weight > 0.f) || !std::isfinite(weight))
    throw InvalidInputError("carveSky: the weight must be positive and finite, got " + std::to_string(weight));
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  cv::compare(sky_depth, sky_depth, sky_rays_, cv::CMP_EQ); // not NaN: open sky
  const cv::Rect rect = cv::boundingRect(sky_rays_);
  const float w = weight * static_cast<float>(config_.carving_weight);
  if (rect.empty() || !(w > 0.f))
    return;
  const float wall_margin = static_cast<float>(volume_.truncation() + volume_.voxelSize());
  const auto inFrontOfWall = [&](int u, int v, float z) {
    return z < sky_depth.ptr<float>(v)[u] - wall_margin ? w : 0.f; // +inf: the whole ray
  };
  carveAlongRays(volume_, sky_rays_, rect, camera, T_world_cam, static_cast<float>(config_.min_depth_m),
                 static_cast<float>(farthestDepth()), config_.max_weight, inFrontOfWall, kAnyBlock);
}

void TsdfIntegrator::carveBeyondRange(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam, float weight) {
  if (!config_.far_carving || !config_.space_carving)
    return;
  frame.validate();
  if (!(weight > 0.f) || !std::isfinite(weight))
    throw InvalidInputError("carveBeyondRange: the weight must be positive and finite, got " + std::to_string(weight));
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  const float w = weight * static_cast<float>(config_.carving_weight);
  const float range = static_cast<float>(config_.max_depth_m);
  const bool own_weights = takesWeightsOf(frame);
  raysBeyondRange(frame.depth, own_weights ? frame.weight : cv::Mat(), range,
                  static_cast<float>(config_.truncation_sigmas), far_rays_);
  const cv::Rect rect = cv::boundingRect(far_rays_);
  if (rect.empty() || !(w > 0.f))
    return;
  // Each far pixel's distance to the nearest pixel that is not: a voxel is carved only where its
  // footprint (half its diagonal, in pixels at its depth) lies wholly within the far rays. Found
  // within the far rays' box grown by a pixel: no pixel beyond that ring of near ones is nearer.
  const cv::Rect around = (rect - cv::Point(1, 1) + cv::Size(2, 2)) & cv::Rect(cv::Point(), far_rays_.size());
  cv::distanceTransform(far_rays_(around), far_distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const float reach_px = 0.5f * std::sqrt(3.f) * static_cast<float>(volume_.voxelSize()) *
                         static_cast<float>(std::max(frame.camera.fx, frame.camera.fy));
  const auto withinFarRays = [&](int u, int v, float z) {
    return far_distance_.at<float>(v - around.y, u - around.x) > reach_px / z + kSilhouetteSlackPx ? w : 0.f;
  };
  // Most blocks the far rays pass lie near their edge, too near for a voxel's footprint to fit.
  tileMaxima(far_distance_, far_tile_max_);
  const auto mayFit = [&](const cv::Rect& footprint, float farthest) {
    return largestOver(far_tile_max_, footprint - around.tl()) > reach_px / farthest + kSilhouetteSlackPx;
  };
  const float bound = range - static_cast<float>(volume_.truncation() + volume_.voxelSize());
  carveAlongRays(volume_, far_rays_, rect, frame.camera, T_world_cam, static_cast<float>(config_.min_depth_m), bound,
                 config_.max_weight, withinFarRays, mayFit);
}

} // namespace msf
