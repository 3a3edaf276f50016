// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/parallel.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include "surface_voxel_walk.h"
#include "voxel_update.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

namespace {

constexpr int kSide = TsdfBlock::kSide;

/// Whether a block's bounding sphere (centre `c` in the camera frame, radius `r`) lies within
/// [min_d, max_d] of depth and its projection, grown by its radius in pixels, meets `rect`.
bool sphereMeetsRect(const Eigen::Vector3f& c, float r, const PinholeCamera& cam, float min_d, float max_d,
                     const cv::Rect& rect) {
  if (c.z() + r < min_d || c.z() - r > max_d)
    return false;
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float z = std::max(c.z() - r, min_d); // the sphere's nearest depth: its widest footprint
  const float r_px = std::max(fx, fy) * r / z;
  const float zc = std::max(c.z(), min_d);
  const float u = fx * c.x() / zc + static_cast<float>(cam.cx), v = fy * c.y() / zc + static_cast<float>(cam.cy);
  return u + r_px >= rect.x && u - r_px <= rect.x + rect.width && v + r_px >= rect.y && v - r_px <= rect.y + rect.height;
}

} // namespace

void TsdfIntegrator::carveSky(const cv::Mat& sky, const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                              float weight, const std::vector<float>& column_depth) {
  if (!config_.sky_carving || !config_.space_carving || sky.empty())
    return;
  if (sky.type() != CV_8UC1 || sky.cols != camera.width || sky.rows != camera.height)
    throw InvalidInputError("carveSky: the sky mask must be CV_8UC1 of the camera's " + std::to_string(camera.width) +
                            "x" + std::to_string(camera.height) + ", not " + std::to_string(sky.cols) + "x" +
                            std::to_string(sky.rows) + " of type " + std::to_string(sky.type()));
  if (!column_depth.empty() && column_depth.size() != static_cast<std::size_t>(camera.width))
    throw InvalidInputError("carveSky: the column depths must be one per image column (" +
                            std::to_string(camera.width) + "), not " + std::to_string(column_depth.size()));
  if (!(weight > 0.f) || !std::isfinite(weight))
    throw InvalidInputError("carveSky: the weight must be positive and finite, got " + std::to_string(weight));
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  const cv::Rect rect = cv::boundingRect(sky);
  const float w = weight * static_cast<float>(config_.carving_weight);
  if (rect.empty() || !(w > 0.f))
    return;
  const float vs = static_cast<float>(volume_.voxelSize()), trunc = static_cast<float>(volume_.truncation());
  const float min_d = static_cast<float>(config_.min_depth_m), max_d = static_cast<float>(config_.farthestDepth());
  const float wall_margin = trunc + vs;
  const auto nearerThanWall = [&](int u, float z) {
    return column_depth.empty() || !(column_depth[static_cast<std::size_t>(u)] > 0.f) ||
           z < column_depth[static_cast<std::size_t>(u)] - wall_margin;
  };
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  const float radius = 0.5f * std::sqrt(3.f) * kSide * vs;
  std::vector<TsdfBlock*> blocks;
  for (const auto& block : volume_.blocks()) {
    if (!block->negative_subblocks)
      continue; // nothing behind a surface: nothing to carve
    const Eigen::Vector3f centre = (block->origin().cast<float>() + Eigen::Vector3f::Constant(3.5f)) * vs;
    if (sphereMeetsRect(T_cam_world * centre, radius, camera, min_d, max_d, rect))
      blocks.push_back(block);
  }
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const std::uint64_t stamp = volume_.beginGeneration();
  const float max_weight = config_.max_weight;
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n)
      detail::carveSurfaceVoxels(*blocks[static_cast<std::size_t>(n)], T_cam_world, vs, stamp,
                                 [&](TsdfVoxel& voxel, const Eigen::Vector3f& p) {
                                   if (p.z() < min_d || p.z() > max_d)
                                     return false;
                                   const int u = static_cast<int>(std::lround(fx * p.x() / p.z() + cx));
                                   const int v = static_cast<int>(std::lround(fy * p.y() / p.z() + cy));
                                   if (u < 0 || v < 0 || u >= camera.width || v >= camera.height ||
                                       !sky.at<std::uint8_t>(v, u) || !nearerThanWall(u, p.z()))
                                     return false;
                                   detail::updateVoxel(voxel, trunc, w, nullptr, max_weight, trunc);
                                   return true;
                                 });
  });
}

} // namespace msf
