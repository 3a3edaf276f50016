// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/elapsed.h>
#include <msf/common/exceptions.h>
#include <msf/common/grid_key.h>
#include <msf/common/limits.h>
#include <msf/reconstruction/plane_distance.h>
#include <msf/reconstruction/silhouette_thickness.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include "surface_voxel_walk.h"
#include "voxel_update.h"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <atomic>
#include <limits>
#include <mutex>
#include <ostream>

namespace msf {

namespace {

/// silhouette_band: neighbours lie on one object unless their depths differ by more than a tenth
/// of the nearer, or by more than the larger of their sigmas (far stereo's noise does not cut a
/// wall into slivers); the band behind stays at least two truncations deep, which keeps the
/// weights of the drop-off around a surface as they were (one truncation cost completeness).
constexpr float kSilhouetteRelativeJump = 0.1f;
constexpr float kSilhouetteSigmas = 1.f;
constexpr float kSilhouetteFloor = 2.f;

/// How far from a surface's plane its band reaches along a grazing ray, either side: a voxel
/// and a half (see computePixelBands), never more than the truncation.
float planeBand(float truncation, float voxel_size) { return std::min(truncation, 1.5f * voxel_size); }

using Clock = std::chrono::steady_clock;

using detail::PixelBand;
using detail::updateVoxel;

constexpr std::uint8_t kUpdated = 1; // TsdfVoxel::flags: changed by this frame, regularized next
constexpr int kSide = TsdfBlock::kSide;

// A block's key: 20 bits an axis (+-2^19 blocks, +-419 km at 0.1 m voxels, see checkReach);
// 60 bits leave 3 for a sub-block.
using BlockKey = GridKey<20>;

/// The blocks of sorted sub-block keys (a block's key and its sub-block in the low 3 bits), each
/// with the mask of its sub-blocks that the keys name.
void groupByBlock(const std::vector<std::uint64_t>& keys, std::vector<GridIndex>& blocks,
                  std::vector<std::uint8_t>& masks) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i == 0 || (keys[i] >> 3) != (keys[i - 1] >> 3)) {
      blocks.push_back(BlockKey::unpack(keys[i] >> 3));
      masks.push_back(0);
    }
    masks.back() |= static_cast<std::uint8_t>(1u << (keys[i] & 7));
  }
}

/// floor(x) as an int, inline: without SSE4.1 (not in x86-64's baseline) std::floor is a call.
inline int floorToInt(float x) {
  const int i = static_cast<int>(x);
  return i - (static_cast<float>(i) > x);
}

/// Amanatides-Woo traversal of the unit cells that the segment a -> b crosses.
template <typename Visit>
void traverseCells(const Eigen::Vector3f& a, const Eigen::Vector3f& b, Visit&& visit) {
  Eigen::Vector3i cell(floorToInt(a.x()), floorToInt(a.y()), floorToInt(a.z()));
  const Eigen::Vector3i end(floorToInt(b.x()), floorToInt(b.y()), floorToInt(b.z()));
  if ((end - cell).cwiseAbs().sum() <= 1) {
    // In one cell, or in two that share a face (a box, convex): the segment crosses those.
    visit(cell);
    if (end != cell)
      visit(end);
    return;
  }
  const Eigen::Vector3f d = b - a;
  Eigen::Vector3i step;
  Eigen::Vector3f t_max, t_delta;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 3; ++i) {
    step[i] = d[i] > 0 ? 1 : (d[i] < 0 ? -1 : 0);
    t_delta[i] = step[i] ? 1.f / std::abs(d[i]) : kInf;
    t_max[i] = step[i] > 0 ? (static_cast<float>(cell[i] + 1) - a[i]) / d[i]
               : step[i] < 0 ? (static_cast<float>(cell[i]) - a[i]) / d[i]
                             : kInf;
  }
  visit(cell);
  // The cell count bounds the loop against float round-off near cell boundaries.
  int remaining = (end - cell).cwiseAbs().sum();
  while (remaining-- > 0) {
    int axis = 0;
    if (t_max[1] < t_max[axis]) axis = 1;
    if (t_max[2] < t_max[axis]) axis = 2;
    if (t_max[axis] > 1.f)
      break;
    cell[axis] += step[axis];
    t_max[axis] += t_delta[axis];
    visit(cell);
  }
}

/// Whether a sphere (centre in the camera frame) may appear in the camera's image: in front of
/// min_depth and its projection, grown by its radius in pixels, overlapping the image.
bool sphereInView(const Eigen::Vector3f& c, float radius, const PinholeCamera& cam, float min_d) {
  if (c.z() + radius < min_d)
    return false;
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float z = std::max(c.z(), min_d);
  const float r_px = std::max(fx, fy) * radius / z;
  const float u = fx * c.x() / z + static_cast<float>(cam.cx), v = fy * c.y() / z + static_cast<float>(cam.cy);
  return u >= -r_px && v >= -r_px && u <= cam.width + r_px && v <= cam.height + r_px;
}

/// Whether the frame's depth carved a point (camera frame) with at least `weight`: it lies in
/// front of min_depth and all four pixels around its projection carved that much, or, on the
/// image's last row or column, the nearest pixel (voxel_update_body.h's sampleDepth, which
/// needs all four pixels' depth).
bool cameraCarved(const cv::Mat& carved, const PinholeCamera& cam, const Eigen::Vector3f& q, float min_d,
                  float weight) {
  if (!(q.z() > min_d))
    return false;
  const float u = static_cast<float>(cam.fx) * q.x() / q.z() + static_cast<float>(cam.cx);
  const float v = static_cast<float>(cam.fy) * q.y() / q.z() + static_cast<float>(cam.cy);
  const float width = static_cast<float>(carved.cols), height = static_cast<float>(carved.rows);
  if (!(u > -0.5f && v > -0.5f && u < width - 0.5f && v < height - 0.5f))
    return false; // outside the image
  if (!(u >= 0.f && v >= 0.f && u + 1.f < width && v + 1.f < height))
    return carved.at<float>(static_cast<int>(std::lround(v)), static_cast<int>(std::lround(u))) >= weight;
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const float* top = carved.ptr<float>(v0) + u0;
  const float* bottom = carved.ptr<float>(v0 + 1) + u0;
  return std::min({top[0], top[1], bottom[0], bottom[1]}) >= weight;
}

} // namespace

namespace {
template <class E, std::size_t N>
E parseWord(const Choice<E> (&choices)[N], const std::string& text, const char* key) {
  if (const auto value = choiceOf(choices, text))
    return *value;
  throw ConfigError(std::string("tsdf_integrator.") + key + " must be " + wordList(choices) + ", not '" + text + "'");
}
} // namespace

const char* toString(TsdfIntegrator::Weighting weighting) { return wordOf(TsdfIntegrator::kWeightings, weighting); }

TsdfIntegrator::Weighting parseWeighting(const std::string& text) {
  return parseWord(TsdfIntegrator::kWeightings, text, "weighting");
}

DepthWeighting::ConstPtr makeDepthWeighting(TsdfIntegrator::Weighting weighting, double depth_sigma_m) {
  switch (weighting) {
  case TsdfIntegrator::Weighting::Constant:
    return std::make_shared<ConstantWeighting>(depth_sigma_m);
  case TsdfIntegrator::Weighting::InverseSquare:
    return std::make_shared<InverseSquareWeighting>(depth_sigma_m);
  case TsdfIntegrator::Weighting::PerPixel:
    break;
  }
  return std::make_shared<PerPixelWeighting>(depth_sigma_m);
}

SignedDistanceModel::ConstPtr makeSignedDistance(TsdfIntegrator::SignedDistance distance,
                                                 const PlaneDistanceConfig& plane) {
  if (distance == TsdfIntegrator::SignedDistance::Projective)
    return std::make_shared<ProjectiveDistance>();
  return std::make_shared<PlaneDistance>(plane);
}

SweepSchedule::ConstPtr makeSweepSchedule(const TsdfIntegrator::Config& config) {
  if (config.solve == TsdfIntegrator::Solve::Argmin)
    return std::make_shared<SweepsToArgmin>(config.argmin_tolerance_m, config.argmin_max_sweeps);
  return std::make_shared<FixedSweeps>(config.sweeps);
}

const char* toString(TsdfIntegrator::SignedDistance distance) {
  return wordOf(TsdfIntegrator::kSignedDistances, distance);
}

TsdfIntegrator::SignedDistance parseSignedDistance(const std::string& text) {
  return parseWord(TsdfIntegrator::kSignedDistances, text, "signed_distance");
}

const char* toString(TsdfIntegrator::LambdaData data) { return wordOf(TsdfIntegrator::kLambdaData, data); }

TsdfIntegrator::LambdaData parseLambdaData(const std::string& text) {
  return parseWord(TsdfIntegrator::kLambdaData, text, "lambda_data");
}

const char* toString(TsdfIntegrator::Solve solve) { return wordOf(TsdfIntegrator::kSolves, solve); }

TsdfIntegrator::Solve parseSolve(const std::string& text) { return parseWord(TsdfIntegrator::kSolves, text, "solve"); }

void TsdfIntegrator::Config::validate() const {
  // Before the range check: the message says what a lambda beyond the range does.
  if (!(lambda >= 0.0 && lambda <= kMaxLambda))
    throw ConfigError("tsdf_integrator.lambda (-lambda) must be 0 .. 1e6 (beyond, eq. 7 flattens the surface "
                      "instead of smoothing it), got " + configValue(lambda));
  checkKeyRanges(*this);
  if (!(max_depth_m > min_depth_m))
    throw ConfigError("tsdf_integrator: need min_depth_m < max_depth_m, got " + configValue(min_depth_m) + " and " +
                      configValue(max_depth_m));
}

double TsdfIntegrator::farthestDepth() const {
  return weighting_->takesFrameWeights() ? std::max(config_.max_depth_m, config_.precise_max_depth_m)
                                         : config_.max_depth_m;
}

TsdfIntegrator::TsdfIntegrator(TsdfVolume& volume) : TsdfIntegrator(volume, Config()) {}

TsdfIntegrator::TsdfIntegrator(TsdfVolume& volume, const Config& config) : volume_(volume) { setConfig(config); }

void TsdfIntegrator::setConfig(const Config& config) {
  config.validate();
  config_ = config;
  weighting_ = makeDepthWeighting(config.weighting, config.depth_sigma_m);
  signed_distance_ = makeSignedDistance(config.signed_distance, config.plane);
  sweep_schedule_ = makeSweepSchedule(config);
}

void TsdfIntegrator::setWeighting(DepthWeighting::ConstPtr weighting) {
  if (!weighting)
    throw InvalidInputError("TsdfIntegrator::setWeighting: no weighting given");
  weighting_ = std::move(weighting);
}

void TsdfIntegrator::setSignedDistance(SignedDistanceModel::ConstPtr model) {
  if (!model)
    throw InvalidInputError("TsdfIntegrator::setSignedDistance: no signed distance given");
  signed_distance_ = std::move(model);
}

void TsdfIntegrator::setSweepSchedule(SweepSchedule::ConstPtr schedule) {
  if (!schedule)
    throw InvalidInputError("TsdfIntegrator::setSweepSchedule: no sweep schedule given");
  sweep_schedule_ = std::move(schedule);
}

bool TsdfIntegrator::takesWeightsOf(const DepthFrame& frame) const {
  return weighting_->takesFrameWeights() && !frame.weight.empty();
}

void TsdfIntegrator::setLambda(double lambda) {
  Config c = config_;
  c.lambda = lambda;
  c.validate();
  config_ = c; // the weighting stays
}

void TsdfIntegrator::checkReach(const Eigen::Isometry3d& T_world_cam) const {
  // Block keys hold 20 bits an axis (BlockKey), and voxel coordinates are ints: a camera
  // whose band reaches beyond that would alias blocks, or overflow a float -> int cast.
  const double reach_m = 0.99 * double(1 << 19) * TsdfBlock::kSide * volume_.voxelSize();
  const double far_m =
      T_world_cam.translation().cwiseAbs().maxCoeff() + farthestDepth() + volume_.truncation();
  if (!(far_m < reach_m))
    throw InvalidInputError("the frame's pose (translation " + std::to_string(T_world_cam.translation().norm()) +
                            " m) with its farthest depth (max_depth_m, precise_max_depth_m) reaches " +
                            std::to_string(far_m) + " m from the origin, beyond the volume's " + std::to_string(reach_m) + " m at " +
                            std::to_string(volume_.voxelSize()) + " m voxels");
}

double TsdfIntegrator::widestBandBehind() const {
  // The band behind a surface (see computePixelBands): at most max(truncation, planeBand over
  // the least plane scale, the depth's sigmas), the sigma from the least weight a pixel can
  // have and still be integrated.
  const double trunc = volume_.truncation(), vs = volume_.voxelSize();
  const double below = signed_distance_->widestBandBelow(planeBand(static_cast<float>(trunc), static_cast<float>(vs)));
  const double least_weight = std::max(static_cast<double>(config_.min_pixel_weight), // the mask
                                       weighting_->leastWeight(config_.max_depth_m));
  double noise = 0.0;
  if (config_.truncation_sigmas > 0.0)
    noise = least_weight > 0.0 ? config_.truncation_sigmas / std::sqrt(least_weight)
                               : std::numeric_limits<double>::infinity();
  return std::max({trunc, below, noise});
}

double TsdfIntegrator::allocationDepth() const {
  // A ray's band is allocated from the depth less its front band to the depth plus its band
  // behind (at most the widest), along the optical axis, for depths up to farthestDepth().
  return farthestDepth() + widestBandBehind();
}

double TsdfIntegrator::reach(const PinholeCamera& camera) const {
  const double trunc = volume_.truncation();
  // A voxel is updated up to its pixel's band behind the depth, and the depth may be the
  // bilinear one of 4 pixels that agree within that band: up to twice the band behind the
  // nearest pixel's depth, itself at most farthestDepth().
  const double behind = 2.0 * widestBandBehind();
  const double far = farthestDepth();
  // The longest ray per metre of depth: through a corner of the image (pixel edges at -0.5
  // and size - 0.5, as the projection's inside test).
  const double du = std::max(std::abs(-0.5 - camera.cx), std::abs(camera.width - 0.5 - camera.cx)) / camera.fx;
  const double dv = std::max(std::abs(-0.5 - camera.cy), std::abs(camera.height - 0.5 - camera.cy)) / camera.fy;
  const double corner = std::sqrt(1.0 + du * du + dv * dv);
  return std::max((far + behind) * corner, config_.max_depth_m + trunc);
}

namespace detail {

/// A frame as integrate's phases read it.
struct FrameView {
  /// The depth the voxels are tested against, without the pixels that weigh too little: rows of
  /// `width` floats like the pixel records (pixels_), so that one index finds a pixel in both.
  const cv::Mat& depth;
  const PinholeCamera& cam;
  int width, height;
  float fx, fy, cx, cy;
  float vs, trunc;
  float min_d, max_d; ///< the depth integrated
};

/// The blocks a frame updates, each with the sub-blocks to project (bit x | y << 1 | z << 2).
struct BlockList {
  std::vector<TsdfBlock*> blocks;
  std::vector<std::uint8_t> masks;
};

/// What updateBlocks did to each block of a BlockList.
struct BlockChanges {
  std::uint64_t stamp = 0;            ///< the volume's generation for this frame
  std::vector<std::uint16_t> updated; ///< voxels updated, per block (0: the block is untouched)
  std::vector<std::uint16_t> listed;  ///< of them, those listed for the regularization
  std::size_t projected = 0;          ///< voxels of the sub-blocks tested
};

} // namespace detail

namespace {

using detail::FrameView;

/// Marks the blocks of a frame's BlockList while space carving adds others, until collectChanged.
constexpr std::uint64_t kListedMark = std::numeric_limits<std::uint64_t>::max();

/// The depth range of a frame is summarized per tile of 8x8 pixels.
constexpr int kTile = 8;

/// Widens the depth range and the widest front band of each 8x8-pixel tile of one image row
/// by its pixels in [min_d, max_d].
inline void widenTileRanges(const float* depth, const PixelBand* bands, const FrameView& view, float* t_min,
                            float* t_max, float* t_band) {
  const int width = view.width, tiles_x = (width + kTile - 1) / kTile;
  const float min_d = view.min_d, max_d = view.max_d;
  for (int tx = 0; tx < tiles_x; ++tx) {
    const float* tile = depth + tx * kTile;
    const PixelBand* tile_band = bands + tx * kTile;
    float lo = t_min[tx], hi = t_max[tx], band = t_band[tx];
    for (int k = 0, n = std::min(kTile, width - tx * kTile); k < n; ++k) {
      const bool valid = tile[k] >= min_d && tile[k] <= max_d; // without branches: holes are unpredictable
      lo = std::min(lo, valid ? tile[k] : std::numeric_limits<float>::infinity());
      hi = std::max(hi, valid ? tile[k] : -std::numeric_limits<float>::infinity());
      band = std::max(band, valid ? tile_band[k].front : 0.f);
    }
    t_min[tx] = lo;
    t_max[tx] = hi;
    t_band[tx] = band;
  }
}

/// The sub-blocks (4^3 voxels) that the band along a pixel's ray crosses. Sub-block coordinates
/// s = (p / vs + 1/2) / 4, so that floor(s) holds p's nearest voxel. A key is the block's
/// (BlockKey) and the sub-block's 3 bits.
struct SubBlockWalk {
  const FrameView& view;
  Eigen::Matrix3f R_wc;
  Eigen::Vector3f t_s; ///< the camera's centre in sub-block coordinates
  float to_sub;        ///< metres to sub-block coordinates
  int stride;          ///< Config::allocation_stride

  /// Appends the keys along the rays of row v's sampled pixels (every stride-th, rows staggered).
  /// Neighbouring pixels cross the same sub-blocks (a grazing band crosses a dozen): keys seen
  /// lately, in a small direct-mapped table, are skipped.
  void row(int v, const float* depth, const PixelBand* bands, std::vector<std::uint64_t>& keys,
           std::array<std::uint64_t, 256>& recent) const {
    const float min_d = view.min_d, max_d = view.max_d;
    for (int u = (v / stride) % stride; u < view.width; u += stride) {
      const float d = depth[u];
      if (!(d >= min_d && d <= max_d))
        continue;
      const Eigen::Vector3f dir_s =
          R_wc * Eigen::Vector3f((u - view.cx) / view.fx, (v - view.cy) / view.fy, 1.f) * to_sub;
      // The band along the ray: `front` nearer than the surface, `behind` beyond it.
      const float z0 = std::max(d - bands[u].front, min_d), z1 = d + bands[u].behind;
      traverseCells(t_s + dir_s * z0, t_s + dir_s * z1, [&](const Eigen::Vector3i& c) {
        const GridIndex b(c.x() >> 1, c.y() >> 1, c.z() >> 1); // floor(c / 2), also below 0
        const std::uint64_t k =
            (BlockKey::pack(b) << 3) | static_cast<std::uint64_t>((c.x() & 1) | ((c.y() & 1) << 1) | ((c.z() & 1) << 2));
        std::uint64_t& slot = recent[(k ^ (k >> 17) ^ (k >> 31)) & (recent.size() - 1)];
        if (slot == k)
          return;
        slot = k;
        keys.push_back(k);
      });
    }
  }
};

/// Which sub-blocks (4^3 voxels) a frame cannot change, by the depth range and widest band of
/// the 8x8-pixel tiles their footprint covers: a sub-block whose footprint sees only bands far
/// in front of or behind it is skipped without projecting its voxels.
struct SubBlockCull {
  const FrameView& view;
  bool carving;
  float radius; ///< of a sub-block's voxel centres
  const float *tile_min, *tile_max, *tile_band;

  /// Whether the sub-block centred at c (camera frame) lies in front of the nearest depth,
  /// outside the image, hidden behind every band, or (without carving) beyond every band.
  bool skips(const Eigen::Vector3f& c) const {
    const float min_d = view.min_d, fx = view.fx, fy = view.fy;
    if (c.z() + radius < min_d)
      return true;
    if (!(c.z() - radius > 0.5f * min_d + 1e-3f))
      return false;
    // Pixel footprint of the bounding sphere: |u(p) - u(c)| <= fx r (1 + |x/z|) / (z - r),
    // +1 px for rounding and bilinear lookups.
    const float inv = radius / (c.z() - radius);
    const float ru = fx * inv * (1.f + std::abs(c.x() / c.z())) + 1.f;
    const float rv = fy * inv * (1.f + std::abs(c.y() / c.z())) + 1.f;
    const float uc = fx * c.x() / c.z() + view.cx, vc = fy * c.y() / c.z() + view.cy;
    const int u0 = std::max(0, floorToInt(uc - ru)), u1 = std::min(view.width - 1, static_cast<int>(uc + ru));
    const int v0 = std::max(0, floorToInt(vc - rv)), v1 = std::min(view.height - 1, static_cast<int>(vc + rv));
    if (u0 > u1 || v0 > v1)
      return true; // outside the image
    const int tx0 = u0 / kTile, tx1 = u1 / kTile, ty0 = v0 / kTile, ty1 = v1 / kTile;
    if ((tx1 - tx0 + 1) * (ty1 - ty0 + 1) > 64)
      return false;
    const int tiles_x = (view.width + kTile - 1) / kTile;
    float dmin = std::numeric_limits<float>::infinity(), dmax = -dmin, band = 0.f;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) {
        const std::size_t t = static_cast<std::size_t>(ty) * tiles_x + tx;
        dmin = std::min(dmin, tile_min[t]);
        dmax = std::max(dmax, tile_max[t]);
        band = std::max(band, tile_band[t]);
      }
    // A bilinear depth lies between its pixels' depths: within [dmin, dmax].
    if (dmax + band < c.z() - radius)
      return true; // every band is in front: the voxels are hidden behind the surface
    return !carving && dmin - band > c.z() + radius; // every band is beyond: the voxels are free space
  }
};

/// The projective update of one block (updateBlocks' work for each): a row of voxels at a time
/// of its listed sub-blocks tested in SIMD lanes against their nearest pixels, and those that
/// pass updated after the whole block is tested. The voxels that pass are gathered first so
/// that their voxels and colours are prefetched while the rest of the block is tested (a map
/// of 10 frames is ~75 MB: the voxels are read from memory, not from a cache).
struct BlockProjection {
  const FrameView& view;
  Eigen::Isometry3d T_cam_world;
  Eigen::Vector3f ex, ey, ez; ///< the grid's axes in the camera frame, a voxel long
  SubBlockCull cull;
  detail::SubBlockTest test_sub_block;
  detail::VoxelTestFrame test_frame;
  detail::BlockUpdate update_block;
  detail::VoxelUpdateFrame update_frame;
  const cv::Mat& color;

  /// Adds the voxels tested to `projected`; lists the changed ones in listed_index and
  /// listed_sdf when they are given (see detail::BlockUpdate).
  detail::VoxelUpdateResult operator()(TsdfBlock& block, std::uint8_t mask, detail::VoxelCandidates& candidates,
                                       std::size_t& projected, std::uint16_t* listed_index, float* listed_sdf) const {
    const Eigen::Vector3f base = (T_cam_world * (block.origin().cast<double>() * view.vs)).cast<float>();
    const detail::VoxelTestBlock test_block{{base.x(), base.y(), base.z()}, {ex.x(), ex.y(), ex.z()},
                                            {ey.x(), ey.y(), ey.z()}, {ez.x(), ez.y(), ez.z()}, block.voxels.data()};
    int n_candidates = 0;
    for (int sub = 0; sub < 8; ++sub) {
      if (!(mask & (1u << sub)))
        continue; // no sampled ray's band crosses this sub-block
      const int sx = 4 * (sub & 1), sy = 2 * (sub & 2), sz = (sub & 4);
      if (cull.skips(base + (ex * (sx + 1.5f) + ey * (sy + 1.5f) + ez * (sz + 1.5f))))
        continue;
      projected += 64;
      n_candidates = test_sub_block(test_frame, test_block, sx, sy, sz, candidates, n_candidates);
    }
    if (!color.empty()) // the voxels were prefetched by the test
      for (int c = 0; c < n_candidates; ++c)
        __builtin_prefetch(color.ptr<std::uint8_t>(candidates.vi[c]) + 3 * candidates.ui[c]);
    return update_block(update_frame, candidates, n_candidates, block.voxels.data(), listed_index, listed_sdf);
  }
};

/// Lists the voxels of `touched` flagged kUpdated (clearing the flag) whose |sdf| is below
/// `band`: their local indices and sdf, block after block, offsets[i] where touched[i]'s begin.
void listFlaggedVoxels(const std::vector<TsdfBlock*>& touched, float band, std::vector<std::uint16_t>& index,
                       std::vector<float>& sdf, std::vector<std::size_t>& offsets) {
  offsets.assign(1, 0);
  index.clear();
  sdf.clear();
  for (TsdfBlock* block : touched) {
    for (int j = 0; j < TsdfBlock::kVoxels; ++j)
      if (block->voxels[j].flags & kUpdated) {
        block->voxels[j].flags &= static_cast<std::uint8_t>(~kUpdated);
        if (!(std::abs(block->voxels[j].sdf) < band))
          continue;
        index.push_back(static_cast<std::uint16_t>(j));
        sdf.push_back(block->voxels[j].sdf);
      }
    offsets.push_back(index.size());
  }
}

/// One Gauss-Seidel step of eq. 7 over `n` changed voxels of `block` (local indices `index`,
/// their means `mean`), its face neighbours `nb` (-x, +x, -y, +y, -z, +z; null where absent)
/// held fixed: x_i = (W_i y_i + lambda * sum_j x_j) / (W_i + lambda * n_i) over the observed
/// 6-neighbours j, W_i the voxel's weight by_weight, else 1. Records the signs in the block when
/// `record_signs`. Returns the largest change of an sdf.
float relaxBlock(TsdfBlock& block, const std::array<TsdfBlock*, 6>& nb, const std::uint16_t* index, const float* mean,
                 std::size_t n, float lambda, bool by_weight, bool record_signs) {
  std::uint8_t signs = 0, negative = 0;
  float change = 0.f;
  for (std::size_t k = 0; k < n; ++k) {
    const int j = index[k];
    const int x = j & 7, yy = (j >> 3) & 7, z = j >> 6;
    float sum = 0.f, count = 0.f;
    // Without branches: whether a neighbour was observed is unpredictable.
    auto add = [&](const TsdfVoxel& q) {
      const bool observed = q.weight > 0.f;
      sum += observed ? q.sdf : 0.f;
      count += observed ? 1.f : 0.f;
    };
    if (x > 0) add(block.voxels[j - 1]); else if (nb[0]) add(nb[0]->at(kSide - 1, yy, z));
    if (x < kSide - 1) add(block.voxels[j + 1]); else if (nb[1]) add(nb[1]->at(0, yy, z));
    if (yy > 0) add(block.voxels[j - kSide]); else if (nb[2]) add(nb[2]->at(x, kSide - 1, z));
    if (yy < kSide - 1) add(block.voxels[j + kSide]); else if (nb[3]) add(nb[3]->at(x, 0, z));
    if (z > 0) add(block.voxels[j - kSide * kSide]); else if (nb[4]) add(nb[4]->at(x, yy, kSide - 1));
    if (z < kSide - 1) add(block.voxels[j + kSide * kSide]); else if (nb[5]) add(nb[5]->at(x, yy, 0));
    float& sdf = block.voxels[j].sdf;
    const float before = sdf;
    const float data = by_weight ? block.voxels[j].weight : 1.f;
    if (count > 0.f)
      sdf = (data * mean[k] + lambda * sum) / (data + lambda * count);
    change = std::max(change, std::abs(sdf - before));
    signs |= sdf < 0.f ? TsdfBlock::kHasNegative : TsdfBlock::kHasPositive;
    negative |= sdf < 0.f ? static_cast<std::uint8_t>(1u << TsdfBlock::subBlockOf(j)) : 0;
  }
  if (record_signs) {
    block.signs |= signs;
    block.negative_subblocks |= negative;
  }
  return change;
}

/// The order in which updateBlocks visits `blocks`: the image's (their centres' 32x32-pixel
/// tiles along a Z-order curve) rather than the keys', so that neighbouring blocks' tests read
/// the same depth and pixel records from the cache. Each block's work is its own: the order
/// changes no result. An entry is the tile (high 32 bits) and the block's index.
std::vector<std::uint64_t> visitOrder(const std::vector<TsdfBlock*>& blocks, const Eigen::Isometry3d& T_cam_world,
                                      const FrameView& view) {
  std::vector<std::uint64_t> order(blocks.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Eigen::Vector3d centre = (blocks[i]->origin().cast<double>() + Eigen::Vector3d::Constant(3.5)) * view.vs;
    const Eigen::Vector3f c = (T_cam_world * centre).cast<float>();
    std::uint64_t tile = 0xffffffffu; // behind the camera: last
    if (c.z() > view.min_d) {
      const auto tu =
          static_cast<std::uint32_t>(std::clamp(view.fx * c.x() / c.z() + view.cx, 0.f, view.width - 1.f)) >> 5;
      const auto tv =
          static_cast<std::uint32_t>(std::clamp(view.fy * c.y() / c.z() + view.cy, 0.f, view.height - 1.f)) >> 5;
      tile = 0;
      for (int b = 0; b < 16; ++b)
        tile |= static_cast<std::uint64_t>(((tu >> b) & 1u) | (((tv >> b) & 1u) << 1)) << (2 * b);
    }
    order[i] = tile << 32 | i;
  }
  std::sort(order.begin(), order.end());
  return order;
}

} // namespace

void TsdfIntegrator::integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam) {
  integrateDepth(frame, T_world_cam);
}

const cv::Mat& TsdfIntegrator::freeSpaceWeights(const DepthFrame& frame) const {
  return takesWeightsOf(frame) && !frame.free_space_weight.empty() ? frame.free_space_weight : weight_;
}

const cv::Mat& TsdfIntegrator::carvedWeights(const DepthFrame& frame, const cv::Mat& integrated) {
  const cv::Mat& free_weight = freeSpaceWeights(frame);
  const float carving_weight = static_cast<float>(config_.carving_weight);
  carved_weight_.create(integrated.size(), CV_32FC1);
  parallelFor(cv::Range(0, integrated.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* depth = integrated.ptr<float>(v);
      const float* f = free_weight.ptr<float>(v);
      float* carved = carved_weight_.ptr<float>(v);
      for (int u = 0; u < integrated.cols; ++u)
        carved[u] = depth[u] > 0.f ? carving_weight * f[u] : 0.f;
    }
  });
  return carved_weight_;
}

std::size_t TsdfIntegrator::bandBlocks(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam) {
  std::vector<GridIndex> blocks;
  std::vector<std::uint8_t> masks;
  groupByBlock(findBandSubBlocks(prepareBands(frame, T_world_cam), T_world_cam), blocks, masks);
  return blocks.size();
}

FrameView TsdfIntegrator::prepareBands(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam) {
  frame.validate();
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  checkReach(T_world_cam);
  const FrameView view = prepareDepth(frame);
  computePixelBands(frame, view);
  return view;
}

cv::Mat TsdfIntegrator::integrateDepth(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam) {
  stats_ = Stats();
  const auto t_start = Clock::now();
  const FrameView view = prepareBands(frame, T_world_cam);
  detail::BlockList list = allocateSubBlocks(findBandSubBlocks(view, T_world_cam));
  if (config_.space_carving)
    addBlocksToCarve(view, T_world_cam, list);
  stats_.allocate_ms = msSince(t_start);

  const auto t_update = Clock::now();
  const detail::BlockChanges changes = updateBlocks(frame, view, T_world_cam, list);
  std::vector<TsdfBlock*> touched;
  std::vector<std::size_t> offsets;
  collectChanged(list, changes, touched, offsets);
  stats_.update_ms = msSince(t_update);

  const auto t_reg = Clock::now();
  if (regularizes())
    regularize(touched, offsets);
  stats_.regularize_ms = msSince(t_reg);
  return view.depth;
}

void TsdfIntegrator::integrateFrame(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam,
                                    const FreeSpace& free) {
  const bool carves_sky = !free.sky_depth.empty() && carvesSky();
  if (carves_sky)
    checkSkyDepth(free.sky_depth, free.sky_camera); // refused before the volume changes
  const cv::Mat integrated = integrateDepth(frame, T_world_cam);
  if (free.scan && carvesWithScans())
    carveWithScan(*free.scan, free.T_world_lidar, free.weight, frame.camera, T_world_cam,
                  carvedWeights(frame, integrated));
  if (carves_sky)
    carveCheckedSky(free.sky_depth, free.sky_camera, T_world_cam, free.weight);
  carveBeyondRange(frame, T_world_cam, free.weight);
}

FrameView TsdfIntegrator::prepareDepth(const DepthFrame& frame) {
  // Each pixel's weight, the inverse variance of its depth (m^-2); pixels weighing less than
  // min_pixel_weight are no depth, for every phase.
  pixelWeights(frame, weight_);
  const float trunc = static_cast<float>(volume_.truncation());
  // Beyond max_depth_m only depth known to within the truncation is integrated, by its own
  // weight: a depth without one is max_depth_m's (depth_sigma_m is no measure of it).
  const bool own_weights = takesWeightsOf(frame);
  const bool precise_only = own_weights && config_.precise_max_depth_m > config_.max_depth_m;
  const bool masked = config_.min_pixel_weight > 0.f || precise_only;
  // A frame's depth may be a view into a wider image: then a copy (see FrameView::depth).
  const bool copied = masked || !frame.depth.isContinuous();
  if (copied)
    frame.depth.copyTo(masked_depth_);
  if (config_.min_pixel_weight > 0.f)
    masked_depth_.setTo(0.f, weight_ < config_.min_pixel_weight);
  if (precise_only)
    masked_depth_.setTo(0.f, (masked_depth_ > config_.max_depth_m) & (weight_ < 1.f / (trunc * trunc)));
  const PinholeCamera& cam = frame.camera;
  return {copied ? masked_depth_ : frame.depth,
          cam,
          cam.width,
          cam.height,
          static_cast<float>(cam.fx),
          static_cast<float>(cam.fy),
          static_cast<float>(cam.cx),
          static_cast<float>(cam.cy),
          static_cast<float>(volume_.voxelSize()),
          trunc,
          static_cast<float>(config_.min_depth_m),
          static_cast<float>(precise_only ? config_.precise_max_depth_m : config_.max_depth_m)};
}

void TsdfIntegrator::computePixelBands(const DepthFrame& frame, const FrameView& view) {
  // Per pixel p of depth d_p, the scale s_p from the projective distance to the distance to the
  // surface's plane (a voxel at depth z on p's ray has sdf (d_p - z) s_p), and the bands along
  // the ray within which voxels are updated, widened to truncation_sigmas standard deviations
  // so that noisy depth is averaged over frames rather than clipped:
  // - in front, the truncation along the ray, or a voxel and a half above the plane;
  // - behind, the truncation along the ray, or a voxel and a half below the plane (marching
  //   cubes needs all 8 corners of a cube the surface crosses, which lie up to
  //   |n_x| + |n_y| + |n_z| voxels from a plane of normal n: a road's camber or a street at an
  //   angle to the grid puts some of them more than one voxel below it) but not the plane's
  //   full length: beyond the surface's edge the plane is free space, and a box seen edge-on
  //   would grow a skirt behind it.
  signed_distance_->pixelScales(view.depth, view.cam, scale_, extent_);
  // One record per pixel, so that a voxel's update reads them from one cache line.
  const int width = view.width;
  pixels_.resize(static_cast<std::size_t>(width) * view.height);
  const float trunc = view.trunc;
  const float sigmas = static_cast<float>(config_.truncation_sigmas);
  // How far from a plane its band reaches along a grazing ray: a voxel and a half either side
  // (free space holds the voxels beyond at +truncation, so the full truncation only costs
  // time; one voxel leaves holes wherever a cube's far corner lies a little deeper).
  const float plane_band = planeBand(trunc, view.vs);
  const cv::Mat& free_weight = freeSpaceWeights(frame);
  const float carving_weight = static_cast<float>(config_.carving_weight);
  // The band behind a thin object's pixels reaches no deeper than the object is wide, and at
  // least kSilhouetteFloor truncations (see Config::silhouette_band).
  const bool silhouette = config_.silhouette_band && sigmas > 0.f;
  if (silhouette)
    silhouetteThickness(view.depth, weight_, view.cam, kSilhouetteRelativeJump, kSilhouetteSigmas, thickness_);
  const float silhouette_floor = kSilhouetteFloor * trunc;
  parallelFor(cv::Range(0, view.height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* s = scale_.ptr<float>(v);
      const float* w = weight_.ptr<float>(v);
      const float* e = extent_.ptr<float>(v);
      const float* f = free_weight.ptr<float>(v);
      const float* thick = silhouette ? thickness_.ptr<float>(v) : nullptr;
      PixelBand* out = &pixels_[static_cast<std::size_t>(v) * width];
      for (int u = 0; u < width; ++u) {
        const float noise = w[u] > 0.f ? sigmas / std::sqrt(w[u]) : 0.f;
        const float front = std::max({trunc, plane_band / s[u], noise});
        const float below = std::min(plane_band / s[u], e[u]); // not past where the surface is seen
        float behind = std::min(front, std::max({trunc, below, noise}));
        if (thick)
          behind = std::min(behind, std::max(silhouette_floor, thick[u]));
        out[u] = {s[u], front, behind, w[u], carving_weight * f[u]};
      }
    }
  });
}

std::vector<std::uint64_t> TsdfIntegrator::findBandSubBlocks(const FrameView& view,
                                                             const Eigen::Isometry3d& T_world_cam) {
  // Only the sub-blocks that the band of a sampled pixel's ray crosses are projected: on
  // KITTI's grazing road a fraction of their blocks. The rows' pass also sums up the tiles'
  // depth ranges for SubBlockCull.
  constexpr int kSub = kSide / 2;
  const float vs = view.vs;
  const SubBlockWalk walk{view, T_world_cam.linear().cast<float>(),
                          (T_world_cam.translation().cast<float>() / vs + Eigen::Vector3f::Constant(0.5f)) / kSub,
                          1.f / (vs * kSub), config_.allocation_stride};
  const int tiles_x = (view.width + kTile - 1) / kTile, tiles_y = (view.height + kTile - 1) / kTile;
  tile_min_.assign(static_cast<std::size_t>(tiles_x) * tiles_y, std::numeric_limits<float>::infinity());
  tile_max_.assign(tile_min_.size(), -std::numeric_limits<float>::infinity());
  tile_band_.assign(tile_min_.size(), 0.f);
  std::vector<std::uint64_t> keys;
  std::mutex keys_mutex;
  // cv::parallel_for_, as the other stages. OpenCV runs a call made while another thread's
  // runs serially (one flag per process): in the pipeline, integration and SGBM then take a
  // core each. An OpenMP team of its own was measured too: no faster on KITTI, and 0.85x on
  // the synthetic street, where both stages' threads time-share the cores and SGBM's strips
  // lose their cache.
  parallelFor(cv::Range(0, tiles_y), [&](const cv::Range& range) {
    std::vector<std::uint64_t> local;
    std::array<std::uint64_t, 256> recent;
    recent.fill(~0ull);
    for (int ty = range.start; ty < range.end; ++ty)
      for (int v = ty * kTile; v < std::min(view.height, (ty + 1) * kTile); ++v) {
        const float* depth = view.depth.ptr<float>(v);
        const PixelBand* bands = &pixels_[static_cast<std::size_t>(v) * view.width];
        const std::size_t t = static_cast<std::size_t>(ty) * tiles_x;
        widenTileRanges(depth, bands, view, &tile_min_[t], &tile_max_[t], &tile_band_[t]);
        if (v % walk.stride == 0)
          walk.row(v, depth, bands, local, recent);
      }
    // Sorted here, in parallel, so that the merged list is shorter and partly in order.
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    const std::lock_guard<std::mutex> lock(keys_mutex);
    keys.insert(keys.end(), local.begin(), local.end());
  });
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

detail::BlockList TsdfIntegrator::allocateSubBlocks(const std::vector<std::uint64_t>& keys) {
  const std::size_t blocks_before = volume_.numBlocks();
  std::vector<GridIndex> block_indices;
  detail::BlockList list;
  groupByBlock(keys, block_indices, list.masks);
  volume_.allocateBlocks(block_indices, list.blocks);
  stats_.blocks_allocated = volume_.numBlocks() - blocks_before;
  return list;
}

void TsdfIntegrator::addBlocksToCarve(const FrameView& view, const Eigen::Isometry3d& T_world_cam,
                                      detail::BlockList& list) {
  // Existing blocks in the view in front of the observed surface: their voxels become free space.
  const Eigen::Isometry3f T_cw = T_world_cam.inverse().cast<float>();
  for (TsdfBlock* b : list.blocks)
    b->stamp = kListedMark; // reset by collectChanged
  // Only sub-blocks that hold a surface (a negative voxel): free space has nothing to carve.
  // Also in the blocks the bands cross: a car that moved on by less than a block left its
  // old rear in the sub-blocks beside its new one.
  std::fill(list.masks.begin(), list.masks.end(), std::uint8_t{0xff});
  // A block may be partly in view when its centre is not: test its bounding sphere.
  const float vs = view.vs, min_d = view.min_d;
  const float radius = 0.5f * std::sqrt(3.f) * kSide * vs;
  for (const auto& block : volume_.blocks()) {
    if (block->stamp == kListedMark || !block->negative_subblocks)
      continue;
    const Eigen::Vector3f c = T_cw * ((block->origin().cast<float>() + Eigen::Vector3f::Constant(3.5f)) * vs);
    if (!sphereInView(c, radius, view.cam, min_d))
      continue;
    const float z = std::max(c.z(), min_d);
    const float u = view.fx * c.x() / z + view.cx, v = view.fy * c.y() / z + view.cy;
    const int ui = std::clamp(static_cast<int>(std::lround(u)), 0, view.width - 1);
    const int vi = std::clamp(static_cast<int>(std::lround(v)), 0, view.height - 1);
    const float d = view.depth.at<float>(vi, ui);
    if (!(d > 0.f) || c.z() - radius < d) {
      list.blocks.push_back(block);
      list.masks.push_back(block->negative_subblocks);
    }
  }
}

detail::BlockChanges TsdfIntegrator::updateBlocks(const DepthFrame& frame, const FrameView& view,
                                                  const Eigen::Isometry3d& T_world_cam, const detail::BlockList& list) {
  const std::vector<TsdfBlock*>& blocks = list.blocks;
  detail::BlockChanges changes;
  changes.stamp = volume_.beginGeneration();
  changes.updated.assign(blocks.size(), 0);
  changes.listed.assign(blocks.size(), 0);
  const bool regularized = regularizes();
  // Changed voxels of each block (local indices), for the regularization.
  if (regularized) {
    changed_index_.resize(blocks.size() * detail::kListStride);
    data_term_.resize(changed_index_.size());
  }
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Matrix3f R = T_cam_world.linear().cast<float>();
  const float vs = view.vs;
  const bool carving = config_.space_carving;
  const bool has_color = !frame.color.empty();
  const float* depth_data = view.depth.ptr<float>(0);
  // The wide kernels read a colour as 4 bytes, one before the pixel's (or after, at pixel 0).
  const bool color_wide = has_color && frame.color.cols >= 2;
  const BlockProjection project{
      view, T_cam_world, R.col(0) * vs, R.col(1) * vs, R.col(2) * vs,
      SubBlockCull{view, carving, 0.5f * std::sqrt(3.f) * 3.f * vs, tile_min_.data(), tile_max_.data(),
                   tile_band_.data()},
      detail::subBlockTest(),
      detail::VoxelTestFrame{view.fx, view.fy, view.cx, view.cy, view.width, view.height, view.min_d, view.max_d,
                             carving, depth_data, pixels_.data()},
      !has_color || color_wide ? detail::blockUpdate() : detail::blockUpdatePortable,
      detail::VoxelUpdateFrame{view.width, view.height, depth_data, pixels_.data(),
                               has_color ? frame.color.ptr<std::uint8_t>(0) : nullptr,
                               has_color ? static_cast<int>(frame.color.step[0]) : 0, config_.interpolate_depth,
                               carving, config_.weight_dropoff, regularized, view.trunc, vs, 1.5f * vs,
                               config_.max_weight, smoothingBand(),
                               static_cast<float>(config_.truncation_sigmas * config_.truncation_sigmas)},
      frame.color};
  const std::vector<std::uint64_t> order = visitOrder(blocks, T_cam_world, view);
  std::atomic<std::size_t> projected_total{0};
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
    detail::VoxelCandidates candidates;
    std::size_t projected = 0;
    for (int n = range.start; n < range.end; ++n) {
      const auto i = static_cast<std::size_t>(order[static_cast<std::size_t>(n)] & 0xffffffffu);
      TsdfBlock& block = *blocks[i];
      const detail::VoxelUpdateResult r =
          project(block, list.masks[i], candidates, projected,
                  regularized ? &changed_index_[i * detail::kListStride] : nullptr,
                  regularized ? &data_term_[i * detail::kListStride] : nullptr);
      changes.updated[i] = static_cast<std::uint16_t>(r.updated);
      changes.listed[i] = static_cast<std::uint16_t>(r.listed);
      if (r.updated) {
        block.stamp = changes.stamp;
        // Only ever set here: a stale bit only costs the mesher a look (see TsdfBlock::signs).
        block.signs |= r.signs;
        block.negative_subblocks |= r.negative;
      }
    }
    projected_total += projected;
  }, std::max(1.0, static_cast<double>(blocks.size()) / 8));
  changes.projected = projected_total;
  return changes;
}

void TsdfIntegrator::collectChanged(const detail::BlockList& list, const detail::BlockChanges& changes,
                                    std::vector<TsdfBlock*>& touched, std::vector<std::size_t>& offsets) {
  const bool regularized = regularizes();
  touched.reserve(list.blocks.size());
  offsets.assign(1, 0);
  std::size_t updated_total = 0;
  for (std::size_t i = 0; i < list.blocks.size(); ++i)
    if (changes.updated[i]) {
      touched.push_back(list.blocks[i]);
      updated_total += changes.updated[i];
      if (regularized) {
        // Compact the lists in place: the source is at or after the destination.
        std::copy_n(&changed_index_[i * detail::kListStride], changes.listed[i], &changed_index_[offsets.back()]);
        std::copy_n(&data_term_[i * detail::kListStride], changes.listed[i], &data_term_[offsets.back()]);
        offsets.push_back(offsets.back() + changes.listed[i]);
      }
    } else if (list.blocks[i]->stamp == kListedMark)
      list.blocks[i]->stamp = changes.stamp;
  stats_.blocks_touched = touched.size();
  stats_.voxels_updated = updated_total;
  stats_.voxels_projected = changes.projected;
}

void TsdfIntegrator::carveWithScan(const ScanFreeSpace& free_space, const Eigen::Isometry3d& T_world_lidar, float weight,
                                   const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                                   const cv::Mat& camera_carved) {
  if (!(config_.scan_carving_m > 0.0) || free_space.empty())
    return;
  if (!(weight > 0.f) || !std::isfinite(weight))
    throw InvalidInputError("carveWithScan: the LiDAR's weight must be positive and finite, got " + std::to_string(weight));
  limits::checkRigid(T_world_lidar, "T_world_lidar (the scan's pose)");
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  const bool camera_everywhere = camera_carved.empty();
  if (!camera_everywhere && (camera_carved.type() != CV_32FC1 || camera_carved.cols != camera.width ||
                             camera_carved.rows != camera.height))
    throw InvalidInputError("carveWithScan: the camera's carved weights must be CV_32FC1 of the camera's " +
                            std::to_string(camera.width) + "x" + std::to_string(camera.height) + ", got type " +
                            std::to_string(camera_carved.type()) + " of " + std::to_string(camera_carved.cols) + "x" +
                            std::to_string(camera_carved.rows));
  const float vs = static_cast<float>(volume_.voxelSize()), trunc = static_cast<float>(volume_.truncation());
  const float min_d = static_cast<float>(config_.min_depth_m), max_range = static_cast<float>(config_.scan_carving_m);
  // A voxel is free when it lies in front of the returns by more than the truncation, a voxel
  // and the scan's skew (a sweep that is not motion-compensated).
  const float margin = trunc + vs + free_space.skew(), w = weight * static_cast<float>(config_.carving_weight);
  if (!(w > 0.f))
    return;
  const Eigen::Isometry3f T_lidar_world = T_world_lidar.inverse().cast<float>();
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  const float radius = 0.5f * std::sqrt(3.f) * kSide * vs;
  std::vector<TsdfBlock*> blocks;
  for (const auto& block : volume_.blocks()) {
    if (!block->negative_subblocks)
      continue;
    const Eigen::Vector3f centre = (block->origin().cast<float>() + Eigen::Vector3f::Constant(3.5f)) * vs;
    if ((T_lidar_world * centre).norm() - radius > max_range ||
        (camera_everywhere && sphereInView(T_cam_world * centre, radius, camera, min_d)))
      continue;
    blocks.push_back(block);
  }
  const std::uint64_t stamp = volume_.beginGeneration();
  const float max_weight = config_.max_weight;
  const Eigen::Isometry3f T_cam_lidar = T_cam_world * T_world_lidar.cast<float>();
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n)
      detail::carveSurfaceVoxels(*blocks[static_cast<std::size_t>(n)], T_lidar_world, vs, stamp,
                                 [&](TsdfVoxel& voxel, const Eigen::Vector3f& p) {
                                   // The projection first: in view it spares most voxels the scan's lookup.
                                   if (!camera_everywhere &&
                                       cameraCarved(camera_carved, camera, T_cam_lidar * p, min_d, w))
                                     return false;
                                   const float nearest = free_space.nearestAround(p);
                                   if (!(nearest > 0.f && p.norm() < nearest - margin))
                                     return false;
                                   updateVoxel(voxel, trunc, w, nullptr, max_weight, trunc, true);
                                   return true;
                                 });
  });
}

void TsdfIntegrator::pixelWeights(const DepthFrame& frame, cv::Mat& weight) {
  if (takesWeightsOf(frame)) {
    weight = frame.weight;
    return;
  }
  computed_weight_.create(frame.depth.size(), CV_32FC1); // never the frame's own buffer
  weight = computed_weight_;
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* d = frame.depth.ptr<float>(v);
    float* w = weight.ptr<float>(v);
    for (int u = 0; u < frame.depth.cols; ++u)
      w[u] = d[u] > 0.f ? weighting_->weight(d[u]) : 0.f;
  }
}

void TsdfIntegrator::integrateRays(const std::vector<Eigen::Vector3f>& points_world,
                                   const std::vector<cv::Vec3b>& colors_bgr, const Eigen::Vector3d& origin_world) {
  if (!colors_bgr.empty() && colors_bgr.size() != points_world.size())
    throw InvalidInputError("integrateRays: " + std::to_string(colors_bgr.size()) + " colours for " +
                            std::to_string(points_world.size()) + " points");
  if (!origin_world.allFinite())
    throw InvalidInputError("integrateRays: the sensor origin is not finite");
  Eigen::Isometry3d T_world_origin = Eigen::Isometry3d::Identity();
  T_world_origin.translation() = origin_world;
  checkReach(T_world_origin);
  stats_ = Stats();
  const auto t_start = Clock::now();
  const std::uint64_t stamp = volume_.beginGeneration();
  const float vs = static_cast<float>(volume_.voxelSize());
  const float trunc = static_cast<float>(volume_.truncation());
  const float min_d = static_cast<float>(config_.min_depth_m), max_d = static_cast<float>(config_.max_depth_m);
  const bool regularized = regularizes();
  const std::uint8_t flag = regularized ? kUpdated : 0;
  const Eigen::Vector3f o = origin_world.cast<float>();
  const std::size_t blocks_before = volume_.numBlocks();
  std::vector<TsdfBlock*> touched;
  TsdfBlock* last = nullptr;
  std::size_t updated = 0;

  // Serial: rays of one scan cross the same voxels, and a scan is small (~120k rays).
  for (std::size_t i = 0; i < points_world.size(); ++i) {
    const Eigen::Vector3f& p = points_world[i];
    if (!p.allFinite())
      continue;
    Eigen::Vector3f dir = p - o;
    const float dist = dir.norm();
    if (!(dist >= min_d && dist <= max_d))
      continue;
    dir /= dist;
    const float w = weighting_->weight(dist);
    const float t0 = config_.space_carving ? 0.f : dist - trunc;
    const Eigen::Vector3f a = (o + dir * t0) / vs + Eigen::Vector3f::Constant(0.5f);
    const Eigen::Vector3f b = (o + dir * (dist + trunc)) / vs + Eigen::Vector3f::Constant(0.5f);
    const std::uint8_t* bgr = colors_bgr.empty() ? nullptr : colors_bgr[i].val;
    traverseCells(a, b, [&](const Eigen::Vector3i& v) {
      const float sdf_raw = dist - (v.cast<float>() * vs - o).dot(dir);
      if (sdf_raw < -trunc)
        return;
      const bool in_band = sdf_raw <= trunc;
      const GridIndex bi = blockOf(v);
      if (!last || last->index != bi) {
        last = &volume_.allocateBlock(bi);
        if (last->stamp != stamp) {
          last->stamp = stamp;
          touched.push_back(last);
        }
      }
      const GridIndex l = v - bi * kSide;
      TsdfVoxel& voxel = last->at(l.x(), l.y(), l.z());
      // A ray of precise depth: it passed the voxels beyond the truncation in front of its point.
      updateVoxel(voxel, in_band ? sdf_raw : trunc, w, in_band ? bgr : nullptr, config_.max_weight, trunc,
                  sdf_raw > trunc);
      voxel.flags |= flag;
      ++updated;
    });
  }
  for (TsdfBlock* block : touched)
    block->updateSigns();
  stats_.blocks_allocated = volume_.numBlocks() - blocks_before;
  stats_.blocks_touched = touched.size();
  stats_.voxels_updated = updated;
  stats_.update_ms = msSince(t_start);
  const auto t_reg = Clock::now();
  if (regularized) {
    std::vector<std::size_t> offsets;
    listFlaggedVoxels(touched, smoothingBand(), changed_index_, data_term_, offsets);
    regularize(touched, offsets);
  }
  stats_.regularize_ms = msSince(t_reg);
}

float TsdfIntegrator::smoothingBand() const {
  // LambdaData::InverseVariance smooths the voxels within half a truncation of their surface,
  // where the zero crossing is; those farther out (free space, the far side of the band) are
  // about half of the changed voxels and hardly move a vertex.
  return config_.lambda_data == LambdaData::InverseVariance ? 0.5f * static_cast<float>(volume_.truncation())
                                                            : std::numeric_limits<float>::infinity();
}

void TsdfIntegrator::regularize(const std::vector<TsdfBlock*>& touched, const std::vector<std::size_t>& offsets) {
  const std::size_t n = touched.size();
  const float lambda = static_cast<float>(config_.lambda);
  const bool by_weight = config_.lambda_data == LambdaData::InverseVariance;
  // Face neighbours of each touched block (-x, +x, -y, +y, -z, +z), looked up once: the
  // map is only read here, so the lookups may run in parallel.
  std::vector<std::array<TsdfBlock*, 6>> neighbours(n);
  parallelFor(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& range) {
    const GridIndex steps[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    for (int i = range.start; i < range.end; ++i)
      for (int k = 0; k < 6; ++k)
        neighbours[i][k] = volume_.findBlock(touched[i]->index + steps[k]);
  }, 16);

  // The stationarity condition of eq. 7 (relaxBlock), over the voxels this frame changed (the
  // others are held fixed). Gauss-Seidel in place, block by block; blocks of one colour of a 3D checkerboard
  // share no face (face neighbours differ by one in one coordinate), so each colour's blocks
  // run in parallel without races.
  std::array<std::vector<std::size_t>, 2> colour;
  for (std::size_t i = 0; i < n; ++i) {
    const GridIndex& b = touched[i]->index;
    colour[(b.x() + b.y() + b.z()) & 1].push_back(i);
  }
  const SweepSchedule& schedule = *sweep_schedule_;
  const int max_sweeps = schedule.maxSweeps();
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    // The sweeps move values towards their neighbours' and can change signs: the last one
    // records them (every one when the last is not known in advance; the flags only add).
    const bool last = !schedule.runsEverySweep() || sweep + 1 == max_sweeps;
    std::atomic<float> largest_change{0.f};
    for (const auto& group : colour) {
      const auto m = static_cast<std::ptrdiff_t>(group.size());
      parallelFor(cv::Range(0, static_cast<int>(m)), [&](const cv::Range& range) {
      for (std::ptrdiff_t g = range.start; g < range.end; ++g) {
        const std::size_t i = group[static_cast<std::size_t>(g)];
        if (g + 1 < m) {
          // The voxels are in memory, not in a cache: fetch the next block's while this one runs.
          const std::size_t next = group[static_cast<std::size_t>(g + 1)];
          for (std::size_t k = offsets[next]; k < offsets[next + 1]; ++k)
            __builtin_prefetch(&touched[next]->voxels[changed_index_[k]]);
        }
        const float change = relaxBlock(*touched[i], neighbours[i], changed_index_.data() + offsets[i],
                                        data_term_.data() + offsets[i], offsets[i + 1] - offsets[i], lambda, by_weight,
                                        last);
        for (float seen = largest_change.load(); change > seen && !largest_change.compare_exchange_weak(seen, change);)
          ;
      }
      }, std::max(1.0, static_cast<double>(m) / 16));
    }
    stats_.regularize_sweeps = sweep + 1;
    if (schedule.converged(largest_change.load())) {
      stats_.regularize_converged = true;
      break;
    }
  }
}

} // namespace msf
