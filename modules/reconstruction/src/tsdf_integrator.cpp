// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/reconstruction/plane_distance.h>
#include <msf/reconstruction/silhouette_thickness.h>
#include <msf/reconstruction/tsdf_integrator.h>

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
/// weights of the drop-off around a surface as they were (one truncation took 0.01-0.15 points
/// of the streets' completeness; two took 0.00-0.06).
constexpr float kSilhouetteRelativeJump = 0.1f;
constexpr float kSilhouetteSigmas = 1.f;
constexpr float kSilhouetteFloor = 2.f;

/// How far from a surface's plane its band reaches along a grazing ray, either side: a voxel
/// and a half (see integrate's step 0), never more than the truncation.
float planeBand(float truncation, float voxel_size) { return std::min(truncation, 1.5f * voxel_size); }

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

using detail::PixelBand;
using detail::updateVoxel;

constexpr std::uint8_t kUpdated = 1; // TsdfVoxel::flags: changed by this frame, regularized next
constexpr int kSide = TsdfBlock::kSide;

// 20 bits per axis: +-524288 blocks, +-419 km at 0.1 m voxels; 60 bits leave 3 for a sub-block.
std::uint64_t packKey(const Eigen::Vector3i& b) {
  constexpr std::int64_t kBias = 1 << 19;
  constexpr std::uint64_t kMask = (1u << 20) - 1;
  return ((static_cast<std::uint64_t>(b.x() + kBias) & kMask) << 40) |
         ((static_cast<std::uint64_t>(b.y() + kBias) & kMask) << 20) | (static_cast<std::uint64_t>(b.z() + kBias) & kMask);
}
GridIndex unpackKey(std::uint64_t k) {
  constexpr std::int64_t kBias = 1 << 19;
  constexpr std::uint64_t kMask = (1u << 20) - 1;
  return {static_cast<int>(static_cast<std::int64_t>((k >> 40) & kMask) - kBias),
          static_cast<int>(static_cast<std::int64_t>((k >> 20) & kMask) - kBias),
          static_cast<int>(static_cast<std::int64_t>(k & kMask) - kBias)};
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

} // namespace

const char* toString(TsdfIntegrator::Weighting weighting) {
  switch (weighting) {
  case TsdfIntegrator::Weighting::Constant: return "constant";
  case TsdfIntegrator::Weighting::InverseSquare: return "inverse_square";
  case TsdfIntegrator::Weighting::PerPixel: return "per_pixel";
  }
  return "?";
}

const char* toString(TsdfIntegrator::SignedDistance distance) {
  return distance == TsdfIntegrator::SignedDistance::Plane ? "plane" : "projective";
}

TsdfIntegrator::SignedDistance parseSignedDistance(const std::string& text) {
  if (text == "plane") return TsdfIntegrator::SignedDistance::Plane;
  if (text == "projective") return TsdfIntegrator::SignedDistance::Projective;
  throw ConfigError("TSDF signed distance '" + text + "' is not plane or projective");
}

TsdfIntegrator::Weighting parseWeighting(const std::string& text) {
  if (text == "constant") return TsdfIntegrator::Weighting::Constant;
  if (text == "inverse_square") return TsdfIntegrator::Weighting::InverseSquare;
  if (text == "per_pixel") return TsdfIntegrator::Weighting::PerPixel;
  throw ConfigError("TSDF weighting '" + text + "' is not constant, inverse_square or per_pixel");
}

const char* toString(TsdfIntegrator::LambdaData data) {
  return data == TsdfIntegrator::LambdaData::InverseVariance ? "inverse_variance" : "uniform";
}

TsdfIntegrator::LambdaData parseLambdaData(const std::string& text) {
  if (text == "uniform") return TsdfIntegrator::LambdaData::Uniform;
  if (text == "inverse_variance") return TsdfIntegrator::LambdaData::InverseVariance;
  throw ConfigError("tsdf_integrator.lambda_data '" + text + "' is not uniform or inverse_variance");
}

const char* toString(TsdfIntegrator::Solve solve) {
  return solve == TsdfIntegrator::Solve::Argmin ? "argmin" : "sweeps";
}

TsdfIntegrator::Solve parseSolve(const std::string& text) {
  if (text == "sweeps") return TsdfIntegrator::Solve::Sweeps;
  if (text == "argmin") return TsdfIntegrator::Solve::Argmin;
  throw ConfigError("tsdf_integrator.solve '" + text + "' is not sweeps or argmin");
}

void TsdfIntegrator::Config::read(const cv::FileNode& node) {
  std::string w = toString(weighting);
  readKey(node, "weighting", w);
  weighting = parseWeighting(w);
  readKey(node, "max_weight", max_weight);
  readKey(node, "depth_sigma_m", depth_sigma_m);
  readKey(node, "min_pixel_weight", min_pixel_weight);
  readKey(node, "truncation_sigmas", truncation_sigmas);
  readKey(node, "space_carving", space_carving);
  readKey(node, "carving_weight", carving_weight);
  readKey(node, "scan_carving_m", scan_carving_m);
  readKey(node, "sky_carving", sky_carving);
  readKey(node, "weight_dropoff", weight_dropoff);
  readKey(node, "silhouette_band", silhouette_band);
  std::string distance = toString(signed_distance);
  readKey(node, "signed_distance", distance);
  signed_distance = parseSignedDistance(distance);
  readKey(node, "plane_step_px", plane.step_px);
  readKey(node, "plane_max_curvature", plane.max_curvature);
  readKey(node, "plane_min_scale", plane.min_scale);
  readKey(node, "lambda", lambda);
  std::string data = toString(lambda_data);
  readKey(node, "lambda_data", data);
  lambda_data = parseLambdaData(data);
  readKey(node, "sweeps", sweeps);
  std::string solve_name = toString(solve);
  readKey(node, "solve", solve_name);
  solve = parseSolve(solve_name);
  readKey(node, "argmin_tolerance_m", argmin_tolerance_m);
  readKey(node, "argmin_max_sweeps", argmin_max_sweeps);
  readKey(node, "min_depth_m", min_depth_m);
  readKey(node, "max_depth_m", max_depth_m);
  readKey(node, "precise_max_depth_m", precise_max_depth_m);
  readKey(node, "interpolate_depth", interpolate_depth);
  readKey(node, "allocation_stride", allocation_stride);
  validate();
}

void TsdfIntegrator::Config::validate() const {
  if (!(max_weight > 0.f))
    throw ConfigError("tsdf_integrator.max_weight must be > 0, got " + std::to_string(max_weight));
  if (!(lambda >= 0.0 && lambda <= kMaxLambda))
    throw ConfigError("tsdf_integrator.lambda (-lambda) must be 0 .. 1e6 (beyond, eq. 7 flattens the surface "
                      "instead of smoothing it), got " + configValue(lambda));
  if (allocation_stride < 1)
    throw ConfigError("tsdf_integrator.allocation_stride must be >= 1, got " + std::to_string(allocation_stride));
  if (!(depth_sigma_m > 0.0) || !std::isfinite(depth_sigma_m))
    throw ConfigError("tsdf_integrator.depth_sigma_m must be > 0, got " + std::to_string(depth_sigma_m));
  if (!(min_pixel_weight >= 0.f) || !std::isfinite(min_pixel_weight))
    throw ConfigError("tsdf_integrator.min_pixel_weight must be >= 0, got " + std::to_string(min_pixel_weight));
  if (!(truncation_sigmas >= 0.0) || !std::isfinite(truncation_sigmas))
    throw ConfigError("tsdf_integrator.truncation_sigmas must be >= 0, got " + std::to_string(truncation_sigmas));
  if (!(carving_weight >= 0.0) || !std::isfinite(carving_weight))
    throw ConfigError("tsdf_integrator.carving_weight must be >= 0, got " + std::to_string(carving_weight));
  if (!(scan_carving_m >= 0.0) || !(scan_carving_m <= kMaxDepthM))
    throw ConfigError("tsdf_integrator.scan_carving_m must be in [0, " + std::to_string(kMaxDepthM) + "] (0 = off), got " +
                      std::to_string(scan_carving_m));
  if (plane.step_px < 1 || plane.step_px > 64)
    throw ConfigError("tsdf_integrator.plane_step_px must be in 1..64, got " + std::to_string(plane.step_px));
  if (!(plane.max_curvature >= 0.f) || !std::isfinite(plane.max_curvature))
    throw ConfigError("tsdf_integrator.plane_max_curvature must be >= 0, got " + std::to_string(plane.max_curvature));
  if (!(plane.min_scale > 0.f && plane.min_scale <= 1.f))
    throw ConfigError("tsdf_integrator.plane_min_scale must be in (0, 1], got " + std::to_string(plane.min_scale));
  if (sweeps < 0 || sweeps > kMaxSweeps)
    throw ConfigError("tsdf_integrator.sweeps (-sweeps) must be 0.." + std::to_string(kMaxSweeps) + ", got " +
                      std::to_string(sweeps));
  if (!(argmin_tolerance_m > 0.0) || !std::isfinite(argmin_tolerance_m))
    throw ConfigError("tsdf_integrator.argmin_tolerance_m must be > 0, got " + std::to_string(argmin_tolerance_m));
  if (argmin_max_sweeps < 1 || argmin_max_sweeps > kMaxArgminSweeps)
    throw ConfigError("tsdf_integrator.argmin_max_sweeps must be 1.." + std::to_string(kMaxArgminSweeps) + ", got " +
                      std::to_string(argmin_max_sweeps));
  if (!(max_depth_m <= kMaxDepthM))
    throw ConfigError("tsdf_integrator.max_depth_m must be at most " + std::to_string(kMaxDepthM) + " m, got " +
                      std::to_string(max_depth_m));
  if (!(precise_max_depth_m >= 0.0) || !(precise_max_depth_m <= kMaxDepthM))
    throw ConfigError("tsdf_integrator.precise_max_depth_m must be in [0, " + std::to_string(kMaxDepthM) +
                      "] m (0: max_depth_m for all depth), got " + std::to_string(precise_max_depth_m));
  if (!(min_depth_m >= 0.0) || !(max_depth_m > min_depth_m))
    throw ConfigError("tsdf_integrator: need 0 <= min_depth_m < max_depth_m, got " + std::to_string(min_depth_m) +
                      " and " + std::to_string(max_depth_m));
}

double TsdfIntegrator::Config::farthestDepth() const {
  return weighting == Weighting::PerPixel ? std::max(max_depth_m, precise_max_depth_m) : max_depth_m;
}

void TsdfIntegrator::Config::print(std::ostream& out) const {
  out << "tsdf_integrator:\n"
      << "  weighting: " << toString(weighting) << "\n"
      << "  max_weight: " << configValue(max_weight) << "\n"
      << "  depth_sigma_m: " << configValue(depth_sigma_m) << "\n"
      << "  min_pixel_weight: " << configValue(min_pixel_weight) << "\n"
      << "  truncation_sigmas: " << configValue(truncation_sigmas) << "\n"
      << "  space_carving: " << configValue(space_carving) << "\n"
      << "  carving_weight: " << configValue(carving_weight) << "\n"
      << "  scan_carving_m: " << configValue(scan_carving_m) << "\n"
      << "  sky_carving: " << configValue(sky_carving) << "\n"
      << "  weight_dropoff: " << configValue(weight_dropoff) << "\n"
      << "  silhouette_band: " << configValue(silhouette_band) << "\n"
      << "  signed_distance: " << toString(signed_distance) << "\n"
      << "  plane_step_px: " << configValue(plane.step_px) << "\n"
      << "  plane_max_curvature: " << configValue(plane.max_curvature) << "\n"
      << "  plane_min_scale: " << configValue(plane.min_scale) << "\n"
      << "  lambda: " << configValue(lambda) << "\n"
      << "  lambda_data: " << toString(lambda_data) << "\n"
      << "  sweeps: " << configValue(sweeps) << "\n"
      << "  solve: " << toString(solve) << "\n"
      << "  argmin_tolerance_m: " << configValue(argmin_tolerance_m) << "\n"
      << "  argmin_max_sweeps: " << configValue(argmin_max_sweeps) << "\n"
      << "  min_depth_m: " << configValue(min_depth_m) << "\n"
      << "  max_depth_m: " << configValue(max_depth_m) << "\n"
      << "  precise_max_depth_m: " << configValue(precise_max_depth_m) << "\n"
      << "  interpolate_depth: " << configValue(interpolate_depth) << "\n"
      << "  allocation_stride: " << configValue(allocation_stride) << "\n";
}

TsdfIntegrator::TsdfIntegrator(TsdfVolume& volume) : volume_(volume) {}

TsdfIntegrator::TsdfIntegrator(TsdfVolume& volume, const Config& config) : volume_(volume) { setConfig(config); }

void TsdfIntegrator::setConfig(const Config& config) {
  config.validate();
  config_ = config;
}

void TsdfIntegrator::setLambda(double lambda) {
  Config c = config_;
  c.lambda = lambda;
  setConfig(c);
}

void TsdfIntegrator::checkReach(const Eigen::Isometry3d& T_world_cam) const {
  // Block keys hold 20 bits an axis (packKey), and voxel coordinates are ints: a camera
  // whose band reaches beyond that would alias blocks, or overflow a float -> int cast.
  const double reach_m = 0.99 * double(1 << 19) * TsdfBlock::kSide * volume_.voxelSize();
  const double far_m =
      T_world_cam.translation().cwiseAbs().maxCoeff() + config_.farthestDepth() + volume_.truncation();
  if (!(far_m < reach_m))
    throw InvalidInputError("the frame's pose (translation " + std::to_string(T_world_cam.translation().norm()) +
                            " m) with its farthest depth (max_depth_m, precise_max_depth_m) reaches " +
                            std::to_string(far_m) + " m from the origin, beyond the volume's " + std::to_string(reach_m) + " m at " +
                            std::to_string(volume_.voxelSize()) + " m voxels");
}

double TsdfIntegrator::widestBandBehind() const {
  // The band behind a surface (see integrate's step 0): at most max(truncation, planeBand over
  // the least plane scale, the depth's sigmas), the sigma from the least weight a pixel can
  // have and still be integrated.
  const double trunc = volume_.truncation(), vs = volume_.voxelSize();
  const double below = config_.signed_distance == SignedDistance::Plane
                           ? planeBand(static_cast<float>(trunc), static_cast<float>(vs)) /
                                 static_cast<double>(config_.plane.min_scale)
                           : 0.0;
  double least_weight = static_cast<double>(config_.min_pixel_weight); // the mask
  const double sigma = config_.depth_sigma_m;
  if (config_.weighting == Weighting::Constant)
    least_weight = std::max(least_weight, 1.0 / (sigma * sigma));
  else if (config_.weighting == Weighting::InverseSquare)
    least_weight = std::max(least_weight, 1.0 / (sigma * sigma * config_.max_depth_m * config_.max_depth_m));
  double noise = 0.0;
  if (config_.truncation_sigmas > 0.0)
    noise = least_weight > 0.0 ? config_.truncation_sigmas / std::sqrt(least_weight)
                               : std::numeric_limits<double>::infinity();
  return std::max({trunc, below, noise});
}

double TsdfIntegrator::allocationDepth() const {
  // A ray's band is allocated from the depth less its front band to the depth plus its band
  // behind (at most the widest), along the optical axis, for depths up to farthestDepth().
  return config_.farthestDepth() + widestBandBehind();
}

double TsdfIntegrator::reach(const PinholeCamera& camera) const {
  const double trunc = volume_.truncation();
  // A voxel is updated up to its pixel's band behind the depth, and the depth may be the
  // bilinear one of 4 pixels that agree within that band: up to twice the band behind the
  // nearest pixel's depth, itself at most farthestDepth().
  const double behind = 2.0 * widestBandBehind();
  const double far = config_.farthestDepth();
  // The longest ray per metre of depth: through a corner of the image (pixel edges at -0.5
  // and size - 0.5, as the projection's inside test).
  const double du = std::max(std::abs(-0.5 - camera.cx), std::abs(camera.width - 0.5 - camera.cx)) / camera.fx;
  const double dv = std::max(std::abs(-0.5 - camera.cy), std::abs(camera.height - 0.5 - camera.cy)) / camera.fy;
  const double corner = std::sqrt(1.0 + du * du + dv * dv);
  return std::max((far + behind) * corner, config_.max_depth_m + trunc);
}

void TsdfIntegrator::integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam) {
  frame.validate();
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  checkReach(T_world_cam);
  stats_ = Stats();
  const auto t_start = Clock::now();

  // Each pixel's weight, the inverse variance of its depth (m^-2); pixels weighing less than
  // min_pixel_weight are no depth, for every step below.
  pixelWeights(frame, weight_);
  const float trunc = static_cast<float>(volume_.truncation());
  // Beyond max_depth_m only depth known to within the truncation is integrated, by its own
  // weight: a depth without one is max_depth_m's (depth_sigma_m is no measure of it).
  const bool own_weights = config_.weighting == Weighting::PerPixel && !frame.weight.empty();
  const bool precise_only = own_weights && config_.precise_max_depth_m > config_.max_depth_m;
  const bool masked = config_.min_pixel_weight > 0.f || precise_only;
  // The depth the voxels are tested against is continuous, rows of `width` floats like the pixel
  // records below, so that one index finds a pixel in both (a frame's depth may be a view into a
  // wider image: then a copy).
  const bool copied = masked || !frame.depth.isContinuous();
  if (copied)
    frame.depth.copyTo(masked_depth_);
  if (config_.min_pixel_weight > 0.f)
    masked_depth_.setTo(0.f, weight_ < config_.min_pixel_weight);
  if (precise_only)
    masked_depth_.setTo(0.f, (masked_depth_ > config_.max_depth_m) & (weight_ < 1.f / (trunc * trunc)));
  const cv::Mat& depth_image = copied ? masked_depth_ : frame.depth;

  const PinholeCamera& cam = frame.camera;
  const int width = cam.width, height = cam.height;
  const float vs = static_cast<float>(volume_.voxelSize());
  const float min_d = static_cast<float>(config_.min_depth_m);
  const float max_d = static_cast<float>(precise_only ? config_.precise_max_depth_m : config_.max_depth_m);
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);

  // 0. Per pixel p of depth d_p, the scale s_p from the projective distance to the distance to
  //    the surface's plane (a voxel at depth z on p's ray has sdf (d_p - z) s_p), and the bands
  //    along the ray within which voxels are updated, widened to truncation_sigmas standard
  //    deviations so that noisy depth is averaged over frames rather than clipped:
  //    - in front, the truncation along the ray, or a voxel and a half above the plane;
  //    - behind, the truncation along the ray, or a voxel and a half below the plane (marching
  //      cubes needs all 8 corners of a cube the surface crosses, which lie up to
  //      |n_x| + |n_y| + |n_z| voxels from a plane of normal n: a road's camber or a street at
  //      an angle to the grid puts some of them more than one voxel below it) but not the
  //      plane's full length: beyond the surface's edge the plane is free space, and a box seen
  //      edge-on would grow a skirt behind it.
  if (config_.signed_distance == SignedDistance::Plane) {
    planeDistanceScale(depth_image, cam, config_.plane, scale_);
    smoothSurfaceExtent(depth_image, config_.plane.max_curvature, extent_);
  } else {
    scale_ = cv::Mat(depth_image.size(), CV_32FC1, cv::Scalar(1.f));
    extent_ = cv::Mat(depth_image.size(), CV_32FC1, cv::Scalar(0.f));
  }
  // One record per pixel, so that a voxel's update reads them from one cache line.
  pixels_.resize(static_cast<std::size_t>(width) * height);
  const float sigmas = static_cast<float>(config_.truncation_sigmas);
  // How far from a plane its band reaches along a grazing ray: a voxel and a half either side
  // (above it, free space holds the voxels beyond at +truncation: the full truncation cost 12 %
  // more time for the same maps; below it, one voxel left holes wherever a cube's far corner
  // lay a little deeper: protocol 4 coverage 0.957 against 0.967 on raw 0009).
  const float plane_band = planeBand(trunc, vs);
  // Free space weighs the frame's free-space weight where it has one (per-pixel weighting).
  const cv::Mat& free_weight = own_weights ? frame.free_space_weight : cv::Mat();
  const float carving_weight = static_cast<float>(config_.carving_weight);
  // The band behind a thin object's pixels reaches no deeper than the object is wide, and at
  // least kSilhouetteFloor truncations (see Config::silhouette_band).
  const bool silhouette = config_.silhouette_band && sigmas > 0.f;
  if (silhouette)
    silhouetteThickness(depth_image, weight_, cam, kSilhouetteRelativeJump, kSilhouetteSigmas, thickness_);
  const float silhouette_floor = kSilhouetteFloor * trunc;
  parallelFor(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* s = scale_.ptr<float>(v);
      const float* w = weight_.ptr<float>(v);
      const float* e = extent_.ptr<float>(v);
      const float* f = free_weight.empty() ? w : free_weight.ptr<float>(v);
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
  const PixelBand* pixel_data = pixels_.data();

  // 1. Sub-blocks (4^3 voxels) that the truncation band of each pixel's ray crosses, found in
  //    parallel: only those are projected below, which on KITTI's grazing road is a fraction
  //    of their blocks. Sub-block coordinates s = (p / vs + 1/2) / 4, so that floor(s) holds
  //    p's nearest voxel. A key is the block (20 bits per axis) and the sub-block's 3 bits.
  const Eigen::Matrix3f R_wc = T_world_cam.linear().cast<float>();
  constexpr int kSub = kSide / 2;
  const float to_sub = 1.f / (vs * kSub);
  const Eigen::Vector3f t_s = (T_world_cam.translation().cast<float>() / vs + Eigen::Vector3f::Constant(0.5f)) / kSub;
  std::vector<std::uint64_t> keys;
  std::mutex keys_mutex;
  const int stride = config_.allocation_stride;
  // Also the depth range of the bands of 8x8-pixel tiles (the least depth less the widest
  // band, the largest depth plus the widest band), in the same pass over the rows: a sub-block
  // of 4^3 voxels whose footprint sees only bands far in front of or behind it is skipped
  // below without projecting its voxels.
  constexpr int kTile = 8;
  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  tile_min_.assign(static_cast<std::size_t>(tiles_x) * tiles_y, std::numeric_limits<float>::infinity());
  tile_max_.assign(tile_min_.size(), -std::numeric_limits<float>::infinity());
  tile_band_.assign(tile_min_.size(), 0.f);
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
    for (int v = ty * kTile; v < std::min(height, (ty + 1) * kTile); ++v) {
      const float* depth = depth_image.ptr<float>(v);
      const PixelBand* band_row = &pixels_[static_cast<std::size_t>(v) * width];
      float* t_min = &tile_min_[static_cast<std::size_t>(ty) * tiles_x];
      float* t_max = &tile_max_[static_cast<std::size_t>(ty) * tiles_x];
      float* t_band = &tile_band_[static_cast<std::size_t>(ty) * tiles_x];
      for (int tx = 0; tx < tiles_x; ++tx) {
        const float* tile = depth + tx * kTile;
        const PixelBand* tile_band = band_row + tx * kTile;
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
      if (v % stride)
        continue;
      for (int u = (v / stride) % stride; u < width; u += stride) {
        const float d = depth[u];
        if (!(d >= min_d && d <= max_d))
          continue;
        const Eigen::Vector3f dir_s = R_wc * Eigen::Vector3f((u - cx) / fx, (v - cy) / fy, 1.f) * to_sub;
        // The band along the ray: `front` nearer than the surface, `behind` beyond it.
        const float z0 = std::max(d - band_row[u].front, min_d), z1 = d + band_row[u].behind;
        traverseCells(t_s + dir_s * z0, t_s + dir_s * z1, [&](const Eigen::Vector3i& c) {
          const GridIndex b(c.x() >> 1, c.y() >> 1, c.z() >> 1); // floor(c / 2), also below 0
          const std::uint64_t k =
              (packKey(b) << 3) | static_cast<std::uint64_t>((c.x() & 1) | ((c.y() & 1) << 1) | ((c.z() & 1) << 2));
          // Neighbouring pixels cross the same sub-blocks (a grazing band crosses a dozen):
          // skip keys seen lately, in a small direct-mapped table.
          std::uint64_t& slot = recent[(k ^ (k >> 17) ^ (k >> 31)) & (recent.size() - 1)];
          if (slot == k)
            return;
          slot = k;
          local.push_back(k);
        });
      }
    }
    // Sorted here, in parallel, so that the merged list is shorter and partly in order.
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    const std::lock_guard<std::mutex> lock(keys_mutex);
    keys.insert(keys.end(), local.begin(), local.end());
  });
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  const std::size_t blocks_before = volume_.numBlocks();
  std::vector<GridIndex> block_indices;
  std::vector<std::uint8_t> masks; // sub-blocks to project, bit x | y << 1 | z << 2
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i == 0 || (keys[i] >> 3) != (keys[i - 1] >> 3)) {
      block_indices.push_back(unpackKey(keys[i] >> 3));
      masks.push_back(0);
    }
    masks.back() |= static_cast<std::uint8_t>(1u << (keys[i] & 7));
  }
  std::vector<TsdfBlock*> blocks;
  volume_.allocateBlocks(block_indices, blocks);
  stats_.blocks_allocated = volume_.numBlocks() - blocks_before;

  if (config_.space_carving) {
    // Existing blocks in the view in front of the observed surface: their voxels become free space.
    const Eigen::Isometry3f T_cw = T_world_cam.inverse().cast<float>();
    const std::uint64_t mark = std::numeric_limits<std::uint64_t>::max();
    for (TsdfBlock* b : blocks)
      b->stamp = mark; // temporary marker, reset below
    // Only sub-blocks that hold a surface (a negative voxel): free space has nothing to carve.
    // Also in the blocks the bands cross: a car that moved on by less than a block left its
    // old rear in the sub-blocks beside its new one.
    std::fill(masks.begin(), masks.end(), std::uint8_t{0xff});
    // A block may be partly in view when its centre is not: test its bounding sphere.
    const float radius = 0.5f * std::sqrt(3.f) * kSide * vs;
    for (const auto& block : volume_.blocks()) {
      if (block->stamp == mark || !block->negative_subblocks)
        continue;
      const Eigen::Vector3f c = T_cw * ((block->origin().cast<float>() + Eigen::Vector3f::Constant(3.5f)) * vs);
      if (!sphereInView(c, radius, cam, min_d))
        continue;
      const float z = std::max(c.z(), min_d);
      const float u = fx * c.x() / z + cx, v = fy * c.y() / z + cy;
      const int ui = std::clamp(static_cast<int>(std::lround(u)), 0, width - 1);
      const int vi = std::clamp(static_cast<int>(std::lround(v)), 0, height - 1);
      const float d = depth_image.at<float>(vi, ui);
      if (!(d > 0.f) || c.z() - radius < d) {
        blocks.push_back(block);
        masks.push_back(block->negative_subblocks);
      }
    }
  }
  stats_.allocate_ms = msSince(t_start);

  // 2. Projective update of every voxel of those blocks, in parallel over blocks.
  const auto t_update = Clock::now();
  const std::uint64_t stamp = volume_.beginGeneration();
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Matrix3f R = T_cam_world.linear().cast<float>();
  const Eigen::Vector3f ex = R.col(0) * vs, ey = R.col(1) * vs, ez = R.col(2) * vs;
  const bool regularized = regularizes();
  // Changed voxels of each block (local indices), for the regularization.
  if (regularized) {
    changed_index_.resize(blocks.size() * detail::kListStride);
    data_term_.resize(changed_index_.size());
  }
  std::vector<std::uint16_t> changed_count(blocks.size(), 0), listed_count(blocks.size(), 0);
  const float smooth_band = smoothingBand();
  const bool bilinear = config_.interpolate_depth;
  const bool carving = config_.space_carving;
  const bool dropoff = config_.weight_dropoff;
  const float colour_band = 1.5f * vs;
  const float max_weight = config_.max_weight;
  const bool has_color = !frame.color.empty();
  std::vector<char> changed(blocks.size(), 0);

  const float sub_radius = 0.5f * std::sqrt(3.f) * 3.f * vs; // voxel centres of a 4^3 sub-block

  std::atomic<std::size_t> projected_total{0};
  const float* depth_data = depth_image.ptr<float>(0);
  const detail::SubBlockTest test_sub_block = detail::subBlockTest();
  const detail::VoxelTestFrame test_frame{fx, fy, cx, cy, width, height, min_d, max_d, carving, depth_data, pixel_data};
  // The wide kernels read a colour as 4 bytes, one before the pixel's (or after, at pixel 0).
  const bool color_wide = has_color && frame.color.cols >= 2;
  const detail::BlockUpdate update_block =
      !has_color || color_wide ? detail::blockUpdate() : detail::blockUpdatePortable;
  const detail::VoxelUpdateFrame update_frame{
      width, height, depth_data, pixel_data, has_color ? frame.color.ptr<std::uint8_t>(0) : nullptr,
      has_color ? static_cast<int>(frame.color.step[0]) : 0, bilinear, carving, dropoff, regularized, trunc, vs,
      colour_band, max_weight, smooth_band};
  // Blocks visited in the image's order (their centres' 32x32-pixel tiles along a Z-order curve)
  // rather than the keys', so that neighbouring blocks' tests read the same depth and pixel
  // records from the cache. Each block's work is its own: the order changes no result.
  std::vector<std::uint64_t> order(blocks.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Eigen::Vector3d centre = (blocks[i]->origin().cast<double>() + Eigen::Vector3d::Constant(3.5)) * vs;
    const Eigen::Vector3f c = (T_cam_world * centre).cast<float>();
    std::uint64_t tile = 0xffffffffu; // behind the camera: last
    if (c.z() > min_d) {
      const auto tu = static_cast<std::uint32_t>(std::clamp(fx * c.x() / c.z() + cx, 0.f, width - 1.f)) >> 5;
      const auto tv = static_cast<std::uint32_t>(std::clamp(fy * c.y() / c.z() + cy, 0.f, height - 1.f)) >> 5;
      tile = 0;
      for (int b = 0; b < 16; ++b)
        tile |= static_cast<std::uint64_t>(((tu >> b) & 1u) | (((tv >> b) & 1u) << 1)) << (2 * b);
    }
    order[i] = tile << 32 | i;
  }
  std::sort(order.begin(), order.end());
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
  // Voxels of one block that passed the nearest-pixel test, gathered before any is updated
  // so that their voxels and colours are prefetched while the rest of the block is tested
  // (a map of 10 frames is ~75 MB: the voxels are read from memory, not from a cache).
  detail::VoxelCandidates candidates;
  std::size_t projected = 0;
  for (int n = range.start; n < range.end; ++n) {
    const auto i = static_cast<std::size_t>(order[static_cast<std::size_t>(n)] & 0xffffffffu);
    TsdfBlock& block = *blocks[i];
    const Eigen::Vector3f base = (T_cam_world * (block.origin().cast<double>() * vs)).cast<float>();
    const detail::VoxelTestBlock test_block{{base.x(), base.y(), base.z()}, {ex.x(), ex.y(), ex.z()},
                                            {ey.x(), ey.y(), ey.z()}, {ez.x(), ez.y(), ez.z()}, block.voxels.data()};
    int n_candidates = 0;
    for (int sub = 0; sub < 8; ++sub) {
      if (!(masks[i] & (1u << sub)))
        continue; // no sampled ray's band crosses this sub-block
      const int sx = 4 * (sub & 1), sy = 2 * (sub & 2), sz = (sub & 4);
      {
        const Eigen::Vector3f c = base + (ex * (sx + 1.5f) + ey * (sy + 1.5f) + ez * (sz + 1.5f));
        if (c.z() + sub_radius < min_d)
          continue;
        if (c.z() - sub_radius > 0.5f * min_d + 1e-3f) {
          // Pixel footprint of the bounding sphere: |u(p) - u(c)| <= fx r (1 + |x/z|) / (z - r),
          // +1 px for rounding and bilinear lookups.
          const float inv = sub_radius / (c.z() - sub_radius);
          const float ru = fx * inv * (1.f + std::abs(c.x() / c.z())) + 1.f;
          const float rv = fy * inv * (1.f + std::abs(c.y() / c.z())) + 1.f;
          const float uc = fx * c.x() / c.z() + cx, vc = fy * c.y() / c.z() + cy;
          const int u0 = std::max(0, floorToInt(uc - ru)), u1 = std::min(width - 1, static_cast<int>(uc + ru));
          const int v0 = std::max(0, floorToInt(vc - rv)), v1 = std::min(height - 1, static_cast<int>(vc + rv));
          if (u0 > u1 || v0 > v1)
            continue; // outside the image
          const int tx0 = u0 / kTile, tx1 = u1 / kTile, ty0 = v0 / kTile, ty1 = v1 / kTile;
          if ((tx1 - tx0 + 1) * (ty1 - ty0 + 1) <= 64) {
            float dmin = std::numeric_limits<float>::infinity(), dmax = -dmin, band = 0.f;
            for (int ty = ty0; ty <= ty1; ++ty)
              for (int tx = tx0; tx <= tx1; ++tx) {
                const std::size_t t = static_cast<std::size_t>(ty) * tiles_x + tx;
                dmin = std::min(dmin, tile_min_[t]);
                dmax = std::max(dmax, tile_max_[t]);
                band = std::max(band, tile_band_[t]);
              }
            // A bilinear depth lies between its pixels' depths: within [dmin, dmax].
            if (dmax + band < c.z() - sub_radius)
              continue; // every band is in front: the voxels are hidden behind the surface
            if (!carving && dmin - band > c.z() + sub_radius)
              continue; // every band is beyond: the voxels are free space
          }
        }
      }
      projected += 64;
      n_candidates = test_sub_block(test_frame, test_block, sx, sy, sz, candidates, n_candidates);
    }
    if (has_color) // the voxels were prefetched by the test
      for (int c = 0; c < n_candidates; ++c)
        __builtin_prefetch(frame.color.ptr<std::uint8_t>(candidates.vi[c]) + 3 * candidates.ui[c]);

    const detail::VoxelUpdateResult r =
        update_block(update_frame, candidates, n_candidates, block.voxels.data(),
                     regularized ? &changed_index_[i * detail::kListStride] : nullptr,
                     regularized ? &data_term_[i * detail::kListStride] : nullptr);
    const int updated = r.updated, listed = r.listed;
    changed_count[i] = static_cast<std::uint16_t>(updated);
    listed_count[i] = static_cast<std::uint16_t>(listed);
    if (updated) {
      block.stamp = stamp;
      // Only ever set here: a stale bit only costs the mesher a look (see TsdfBlock::signs).
      block.signs |= r.signs;
      block.negative_subblocks |= r.negative;
      changed[i] = 1;
    }
  }
  projected_total += projected;
  }, std::max(1.0, static_cast<double>(blocks.size()) / 8));
  std::vector<TsdfBlock*> touched;
  touched.reserve(blocks.size());
  std::vector<std::size_t> offsets{0};
  std::size_t updated_total = 0;
  for (std::size_t i = 0; i < blocks.size(); ++i)
    if (changed[i]) {
      touched.push_back(blocks[i]);
      updated_total += changed_count[i];
      if (regularized) {
        // Compact the lists in place: the source is at or after the destination.
        std::copy_n(&changed_index_[i * detail::kListStride], listed_count[i], &changed_index_[offsets.back()]);
        std::copy_n(&data_term_[i * detail::kListStride], listed_count[i], &data_term_[offsets.back()]);
        offsets.push_back(offsets.back() + listed_count[i]);
      }
    } else if (blocks[i]->stamp == std::numeric_limits<std::uint64_t>::max())
      blocks[i]->stamp = stamp;
  stats_.blocks_touched = touched.size();
  stats_.voxels_updated = updated_total;
  stats_.voxels_projected = projected_total;
  stats_.update_ms = msSince(t_update);

  const auto t_reg = Clock::now();
  if (regularized)
    regularize(touched, offsets);
  stats_.regularize_ms = msSince(t_reg);
}

void TsdfIntegrator::carveWithScan(const ScanFreeSpace& free_space, const Eigen::Isometry3d& T_world_lidar, float weight,
                                   const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam) {
  if (!(config_.scan_carving_m > 0.0) || free_space.empty())
    return;
  if (!(weight > 0.f) || !std::isfinite(weight))
    throw InvalidInputError("carveWithScan: the LiDAR's weight must be positive and finite, got " + std::to_string(weight));
  limits::checkRigid(T_world_lidar, "T_world_lidar (the scan's pose)");
  limits::checkRigid(T_world_cam, "T_world_cam (the frame's pose)");
  const float vs = static_cast<float>(volume_.voxelSize()), trunc = static_cast<float>(volume_.truncation());
  const float min_d = static_cast<float>(config_.min_depth_m), max_range = static_cast<float>(config_.scan_carving_m);
  // A voxel is free when it lies in front of the returns by more than the truncation, a voxel
  // and the sweep's skew: a sweep is not motion-compensated (KITTI's are not), and at 13 m/s
  // its returns lie up to 0.65 m from where the scan's one pose puts them.
  constexpr float kSweepSkewM = 0.6f;
  const float margin = trunc + vs + kSweepSkewM, w = weight * static_cast<float>(config_.carving_weight);
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
    if ((T_lidar_world * centre).norm() - radius > max_range || sphereInView(T_cam_world * centre, radius, camera, min_d))
      continue;
    blocks.push_back(block);
  }
  const std::uint64_t stamp = volume_.beginGeneration();
  const float max_weight = config_.max_weight;
  parallelFor(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n) {
      TsdfBlock& block = *blocks[static_cast<std::size_t>(n)];
      const Eigen::Vector3f origin = T_lidar_world * (block.origin().cast<float>() * vs);
      const Eigen::Matrix3f axes = T_lidar_world.linear() * vs;
      bool changed = false;
      for (int sub = 0; sub < 8; ++sub) {
        if (!(block.negative_subblocks & (1u << sub)))
          continue;
        const int sx = 4 * (sub & 1), sy = 2 * (sub & 2), sz = sub & 4;
        for (int z = sz; z < sz + 4; ++z)
          for (int y = sy; y < sy + 4; ++y)
            for (int x = sx; x < sx + 4; ++x) {
              TsdfVoxel& voxel = block.at(x, y, z);
              if (!(voxel.sdf < 0.f && voxel.weight > 0.f))
                continue;
              const Eigen::Vector3f p = origin + axes * Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y),
                                                                        static_cast<float>(z));
              const float nearest = free_space.nearestAround(p);
              if (nearest > 0.f && p.norm() < nearest - margin) {
                updateVoxel(voxel, trunc, w, nullptr, max_weight, trunc);
                changed = true;
              }
            }
      }
      if (changed) {
        block.updateSigns();
        block.stamp = stamp;
      }
    }
  });
}

float TsdfIntegrator::depthWeight(float depth) const {
  const float sigma = static_cast<float>(config_.depth_sigma_m);
  return config_.weighting == Weighting::InverseSquare ? 1.f / (sigma * sigma * depth * depth) : 1.f / (sigma * sigma);
}

void TsdfIntegrator::pixelWeights(const DepthFrame& frame, cv::Mat& weight) {
  if (config_.weighting == Weighting::PerPixel && !frame.weight.empty()) {
    weight = frame.weight;
    return;
  }
  computed_weight_.create(frame.depth.size(), CV_32FC1); // never the frame's own buffer
  weight = computed_weight_;
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* d = frame.depth.ptr<float>(v);
    float* w = weight.ptr<float>(v);
    for (int u = 0; u < frame.depth.cols; ++u)
      w[u] = d[u] > 0.f ? depthWeight(d[u]) : 0.f;
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
    const float w = depthWeight(dist);
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
      updateVoxel(voxel, in_band ? sdf_raw : trunc, w, in_band ? bgr : nullptr, config_.max_weight, trunc);
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
    const float smooth_band = smoothingBand();
    std::vector<std::size_t> offsets{0};
    changed_index_.clear();
    data_term_.clear();
    for (TsdfBlock* block : touched) {
      for (int j = 0; j < TsdfBlock::kVoxels; ++j)
        if (block->voxels[j].flags & kUpdated) {
          block->voxels[j].flags = 0;
          if (!(std::abs(block->voxels[j].sdf) < smooth_band))
            continue;
          changed_index_.push_back(static_cast<std::uint16_t>(j));
          data_term_.push_back(block->voxels[j].sdf);
        }
      offsets.push_back(changed_index_.size());
    }
    regularize(touched, offsets);
  }
  stats_.regularize_ms = msSince(t_reg);
}

float TsdfIntegrator::smoothingBand() const {
  // LambdaData::InverseVariance smooths the voxels within half a truncation of their surface,
  // where the zero crossing is; those farther out (free space, the far side of the band) are
  // about half of the changed voxels and hardly move a vertex (KITTI and street maps within
  // 0.002 m and 0.1 points of smoothing them all, in 45 % less time).
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

  // x_i = (W_i y_i + lambda * sum_j x_j) / (W_i + lambda * n_i) over observed 6-neighbours j
  // (W_i = 1 for LambdaData::Uniform): the
  // stationarity condition of eq. 7, over the voxels this frame changed (the others are held
  // fixed). Gauss-Seidel in place, block by block; blocks of one colour of a 3D checkerboard
  // share no face (face neighbours differ by one in one coordinate), so each colour's blocks
  // run in parallel without races.
  std::array<std::vector<std::size_t>, 2> colour;
  for (std::size_t i = 0; i < n; ++i) {
    const GridIndex& b = touched[i]->index;
    colour[(b.x() + b.y() + b.z()) & 1].push_back(i);
  }
  const bool argmin = config_.solve == Solve::Argmin;
  const int max_sweeps = argmin ? config_.argmin_max_sweeps : config_.sweeps;
  const auto tolerance = static_cast<float>(config_.argmin_tolerance_m);
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    // The sweeps move values towards their neighbours' and can change signs: the last one
    // records them (every one when the last is not known in advance; the flags only add).
    const bool last = argmin || sweep + 1 == max_sweeps;
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
        TsdfBlock& block = *touched[i];
        const auto& nb = neighbours[i];
        std::uint8_t signs = 0, negative = 0;
        float change = 0.f;
        for (std::size_t k = offsets[i]; k < offsets[i + 1]; ++k) {
          const int j = changed_index_[k];
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
            sdf = (data * data_term_[k] + lambda * sum) / (data + lambda * count);
          change = std::max(change, std::abs(sdf - before));
          signs |= sdf < 0.f ? TsdfBlock::kHasNegative : TsdfBlock::kHasPositive;
          negative |= sdf < 0.f ? static_cast<std::uint8_t>(1u << TsdfBlock::subBlockOf(j)) : 0;
        }
        if (last) {
          block.signs |= signs;
          block.negative_subblocks |= negative;
        }
        for (float seen = largest_change.load(); change > seen && !largest_change.compare_exchange_weak(seen, change);)
          ;
      }
      }, std::max(1.0, static_cast<double>(m) / 16));
    }
    stats_.regularize_sweeps = sweep + 1;
    if (argmin && largest_change.load() <= tolerance) {
      stats_.regularize_converged = true;
      break;
    }
  }
}

} // namespace msf
