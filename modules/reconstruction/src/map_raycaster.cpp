// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/parallel.h>
#include <msf/reconstruction/map_raycaster.h>
#include <msf/reconstruction/tsdf_block.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace msf {

void MapPriorConfig::validate() const {
  checkKeyRanges(*this);
  if (!(max_depth_m > min_depth_m))
    throw ConfigError("map_prior.max_depth_m (" + std::to_string(max_depth_m) + ") must exceed min_depth_m (" +
                      std::to_string(min_depth_m) + ")");
}

MapRaycaster::MapRaycaster(const TsdfVolume& volume, const MapPriorConfig& config)
    : volume_(volume), config_(config) {
  config_.validate();
}

namespace {

constexpr int kSubBlockSide = TsdfBlock::kSide / 2; // the cubes of TsdfBlock::negative_subblocks

/// The ray parameter at which the ray o + d t (in voxels) leaves the cube of `side` voxels
/// (a block, or a sub-block of it) that holds voxel v.
float cellExit(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const GridIndex& v, int side) {
  float exit = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a) {
    const float lo = static_cast<float>(floorDiv(v[a], side) * side) - 0.5f, hi = lo + static_cast<float>(side);
    if (d[a] > 0.f)
      exit = std::min(exit, (hi - o[a]) / d[a]);
    else if (d[a] < 0.f)
      exit = std::min(exit, (lo - o[a]) / d[a]);
  }
  return exit;
}

/// x rounded to the nearest integer, halves up: inline, where std::lround is a library call.
int roundToInt(float x) {
  const float shifted = x + 0.5f;
  const int truncated = static_cast<int>(shifted);
  return truncated - (shifted < static_cast<float>(truncated));
}

/// Voxel look-ups along one ray: most fall in the block of the one before.
class RayVoxels {
public:
  RayVoxels(const TsdfVolume& volume, float min_weight) : volume_(volume), min_weight_(min_weight) {}

  /// The voxel, or null when its block is not allocated.
  const TsdfVoxel* find(const GridIndex& v) {
    const GridIndex b = blockOf(v);
    if (!block_ || block_->index != b)
      block_ = volume_.findBlock(b);
    if (!block_)
      return nullptr;
    const GridIndex l = v - b * TsdfBlock::kSide;
    return &block_->at(l.x(), l.y(), l.z());
  }
  /// The voxel nearest to p (in voxels).
  const TsdfVoxel* nearest(const Eigen::Vector3f& p, GridIndex& v) {
    v = GridIndex(roundToInt(p.x()), roundToInt(p.y()), roundToInt(p.z()));
    return find(v);
  }
  /// Whether the sub-block of v, the last voxel found, may hold a surface: an observed voxel with sdf < 0.
  bool mayHoldSurface(const GridIndex& v) const {
    const GridIndex l = v - block_->origin();
    return block_->negative_subblocks & (1u << TsdfBlock::subBlockOf(TsdfBlock::linear(l.x(), l.y(), l.z())));
  }
  bool known(const TsdfVoxel* voxel) const { return voxel && voxel->weight > min_weight_; }

  /// Trilinear signed distance at p (in voxels) and the least weight of its 8 voxels; false
  /// when one is missing or not known beyond min_weight.
  bool trilinear(const Eigen::Vector3f& p, float& sdf, float& weight) {
    const Eigen::Vector3f base = p.array().floor();
    const Eigen::Vector3f f = p - base;
    const GridIndex b(static_cast<int>(base.x()), static_cast<int>(base.y()), static_cast<int>(base.z()));
    sdf = 0.f;
    weight = std::numeric_limits<float>::infinity();
    for (int corner = 0; corner < 8; ++corner) {
      const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
      const TsdfVoxel* voxel = find(b + GridIndex(dx, dy, dz));
      if (!known(voxel))
        return false;
      const float share = (dx ? f.x() : 1.f - f.x()) * (dy ? f.y() : 1.f - f.y()) * (dz ? f.z() : 1.f - f.z());
      sdf += share * voxel->sdf;
      weight = std::min(weight, voxel->weight);
    }
    return true;
  }

private:
  const TsdfVolume& volume_;
  float min_weight_;
  const TsdfBlock* block_ = nullptr;
};

/// The crossing between ray parameters a (in front, its voxel's distance sdf_a) and b (behind,
/// sdf_b) of the ray o + d t (in voxels). The voxels' distances are their centres' and may be
/// clamped at the truncation: from a voxel before a (a's nearest voxel may lie in front of the
/// surface while a itself lies behind it) to a voxel beyond b the ray is walked in half voxels on
/// the trilinear distance and interpolated between the first two samples that straddle the
/// surface (`weight` becomes the least of their voxels'); the samples' own estimate where none do.
float refineCrossing(RayVoxels& voxels, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float a, float sdf_a,
                     float b, float sdf_b, float& weight) {
  const float estimate = a + (b - a) * sdf_a / (sdf_a - sdf_b);
  const float half_voxel = 0.5f / d.norm();
  float t_front = -1.f, sdf_front = 0.f, w_front = 0.f;
  for (float t = a - 2.f * half_voxel; t <= b + 2.f * half_voxel; t += half_voxel) {
    float sdf, w;
    if (!voxels.trilinear(o + d * t, sdf, w)) {
      t_front = -1.f;
      continue;
    }
    if (sdf >= 0.f) {
      t_front = t;
      sdf_front = sdf;
      w_front = w;
    } else if (t_front >= 0.f) {
      weight = std::min(w_front, w);
      return t_front + (t - t_front) * sdf_front / (sdf_front - sdf);
    }
  }
  return estimate;
}

} // namespace

bool MapRaycaster::castRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_near, float t_far,
                           float& t, float& weight) const {
  const float vs = static_cast<float>(volume_.voxelSize());
  const Eigen::Vector3f o = origin / vs, d = direction / vs; // in voxels per metre of t
  RayVoxels voxels(volume_, config_.min_weight);
  const float nudge = 0.01f * vs; // past a cell's face, into the next one
  float t_before = -1.f, sdf_before = 0.f; // the last known sample in front of a surface
  for (t = t_near; t <= t_far;) {
    GridIndex v;
    const TsdfVoxel* voxel = voxels.nearest(o + d * t, v);
    if (!voxel) { // no block: no surface before the ray leaves it
      t_before = -1.f;
      t = std::max(t, cellExit(o, d, v, TsdfBlock::kSide)) + nudge;
      continue;
    }
    if (!voxels.mayHoldSurface(v)) { // no crossing in its sub-block: on to its last sample there
      const float last = cellExit(o, d, v, kSubBlockSide) - nudge;
      if (last > t) {
        t = last;
        continue;
      }
    }
    if (!voxels.known(voxel)) {
      t_before = -1.f;
      t += vs;
      continue;
    }
    if (voxel->sdf < 0.f && t_before >= 0.f) {
      weight = voxel->weight;
      t = refineCrossing(voxels, o, d, t_before, sdf_before, t, voxel->sdf, weight);
      return true;
    }
    if (voxel->sdf >= 0.f) {
      t_before = t;
      sdf_before = voxel->sdf;
    }
    t += std::max(vs, 0.8f * voxel->sdf); // free space: no surface nearer than its distance
  }
  return false;
}

void MapRaycaster::render(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, const cv::Mat& mask,
                          cv::Mat& depth, cv::Mat& weight) const {
  if (!camera.valid())
    throw InvalidInputError("MapRaycaster::render: the camera is not valid (fx, fy > 0, a size)");
  limits::checkRigid(T_world_cam, "MapRaycaster::render: T_world_cam (the view's pose)");
  if (mask.type() != CV_8UC1 || mask.cols != camera.width || mask.rows != camera.height)
    throw InvalidInputError("MapRaycaster::render: the mask must be CV_8UC1 of the camera's " +
                            std::to_string(camera.width) + "x" + std::to_string(camera.height) + " pixels");
  depth.create(mask.size(), CV_32FC1);
  depth.setTo(0.f);
  weight.create(mask.size(), CV_32FC1);
  weight.setTo(0.f);
  const Eigen::Vector3f origin = T_world_cam.translation().cast<float>();
  const Eigen::Matrix3f R = T_world_cam.linear().cast<float>();
  parallelFor(cv::Range(0, mask.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const std::uint8_t* m = mask.ptr<std::uint8_t>(v);
      float* z = depth.ptr<float>(v);
      float* w = weight.ptr<float>(v);
      for (int u = 0; u < mask.cols; ++u) {
        if (!m[u])
          continue;
        const Eigen::Vector3f ray(static_cast<float>((u - camera.cx) / camera.fx),
                                  static_cast<float>((v - camera.cy) / camera.fy), 1.f);
        const float length = ray.norm(); // metres along the ray per metre of depth
        float t;
        if (castRay(origin, R * ray / length, static_cast<float>(config_.min_depth_m) * length,
                    static_cast<float>(config_.max_depth_m) * length, t, w[u]))
          z[u] = t / length;
        else
          w[u] = 0.f;
      }
    }
  });
}

} // namespace msf
