// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/camera_renderer.h>
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/kitti_sky.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace msf::synthetic {

namespace {

constexpr float kMaxDepthM = 1000.f;
constexpr float kExposure = 1.0f;
constexpr float kAmbient = 0.42f;
constexpr float kSun = 0.75f;

/// A rectified camera placed in the world: every rectified camera shares camera 0's
/// orientation, so a pixel's ray is R_world_cam0 * K^-1 (u, v, 1) from its centre, and t
/// along it is the depth in that camera.
struct CameraModel {
  V3 center;
  float R[9];
  float fx, fy, cx, cy;
  int width, height;

  V3 rotate(float x, float y, float z) const {
    return {R[0] * x + R[1] * y + R[2] * z, R[3] * x + R[4] * y + R[5] * z, R[6] * x + R[7] * y + R[8] * z};
  }
  V3 direction(float u, float v) const { return rotate((u - cx) / fx, (v - cy) / fy, 1.f); }
};

CameraModel cameraModel(const Calibration& calibration, int camera, const Eigen::Isometry3d& T_world_cam0) {
  Calibration::checkCamera(camera);
  CameraModel m;
  const Eigen::Vector3d c = T_world_cam0 * calibration.cameraCenter(camera);
  m.center = {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
  const Eigen::Matrix3d R = T_world_cam0.linear();
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      m.R[3 * r + k] = static_cast<float>(R(r, k));
  m.fx = static_cast<float>(calibration.fx(camera));
  m.fy = static_cast<float>(calibration.fy(camera));
  m.cx = static_cast<float>(calibration.cx(camera));
  m.cy = static_cast<float>(calibration.cy(camera));
  const cv::Size size = calibration.requireImageSize();
  m.width = size.width;
  m.height = size.height;
  return m;
}

/// Direction towards the sun (world, y down): high, from the front left.
const V3 kSunDirection = normalized({-0.45f, -0.8f, 0.4f});

struct Radiance {
  float r = 0.f, g = 0.f, b = 0.f;
};

Radiance sky(V3 dir) {
  const float up = std::clamp(-dir.y / norm(dir), 0.f, 1.f);
  const float t = std::min(1.f, up * 2.5f);
  return {0.82f - 0.42f * t, 0.86f - 0.30f * t, 0.92f - 0.12f * t};
}

/// The sky of synthetic.sky: the pale default, or KITTI's (kittiSky) with its clouds drawn from the seed.
struct SkyLook {
  bool kitti = false;
  std::uint32_t seed = 0;
  Radiance operator()(V3 dir) const {
    if (!kitti)
      return sky(dir);
    const SkyRadiance r = kittiSky(dir, seed);
    return {r.r, r.g, r.b};
  }
};

/// What one ray sees: its radiance, which surface (a key that differs across geometric
/// edges), and the exact depth and object id for the ground truth.
struct Sample {
  Radiance radiance;
  std::int32_t surface = 0; ///< 0 sky; otherwise 8 * (primitive + 3) + face
  float depth = 0.f;        ///< 0 for the sky
  std::int32_t object = 0;
};

/// Traces one ray; step_x / step_y are the ray's spread for one sample step in the image.
Sample trace(const SceneSnapshot& scene, const Ray& ray, V3 step_x, V3 step_y, const SkyLook& look) {
  Sample out;
  Hit hit;
  if (!scene.intersect(ray, 0.f, kMaxDepthM, hit)) {
    out.radiance = look(ray.dir);
    return out;
  }
  const V3 world = ray.origin + ray.dir * hit.t;
  // Ray differentials: how far the hit point moves on the surface for one sample step.
  const float dn = dot(ray.dir, hit.normal);
  Footprint fp;
  if (std::fabs(dn) > 1e-6f) {
    fp.dx = (step_x - ray.dir * (dot(step_x, hit.normal) / dn)) * hit.t;
    fp.dy = (step_y - ray.dir * (dot(step_y, hit.normal) / dn)) * hit.t;
  }
  const SurfaceResponse s = scene.shade(hit, world, fp);
  const V3 n = dn > 0.f ? hit.normal * -1.f : hit.normal;
  const float light = kAmbient + kSun * std::max(0.f, dot(n, kSunDirection));
  out.radiance = {s.r * light, s.g * light, s.b * light};
  out.surface = 8 * (hit.primitive + 3) + hit.face;
  out.depth = hit.t;
  const Primitive* solid = scene.primitive(hit.primitive);
  out.object = solid ? static_cast<std::int32_t>(solid->object) : 0;
  return out;
}

/// 255 * x^(1/2.2) tabulated over [0, 1]: pow per pixel and channel is a measurable cost.
class GammaTable {
public:
  GammaTable() {
    for (int i = 0; i <= kSize; ++i)
      table_[static_cast<std::size_t>(i)] = 255.f * std::pow(static_cast<float>(i) / kSize, 1.f / 2.2f);
  }
  float operator()(float linear) const {
    const float x = std::clamp(linear * kExposure, 0.f, 1.f) * kSize;
    const int i = std::min(static_cast<int>(x), kSize - 1);
    const float t = x - static_cast<float>(i);
    return table_[static_cast<std::size_t>(i)] + t * (table_[static_cast<std::size_t>(i) + 1] - table_[static_cast<std::size_t>(i)]);
  }

private:
  static constexpr int kSize = 4096;
  std::array<float, kSize + 1> table_;
};

/// std::lround (halves away from zero) for |x| < 2^23 without the library call: x minus its
/// truncation is exact there.
inline long roundHalfAway(float x) {
  long r = static_cast<long>(x);
  const float fraction = x - static_cast<float>(r);
  if (fraction >= 0.5f)
    ++r;
  else if (fraction <= -0.5f)
    --r;
  return r;
}

inline std::uint8_t toByte(const GammaTable& gamma, float linear, float noise) {
  return static_cast<std::uint8_t>(std::clamp(roundHalfAway(gamma(linear) + noise), 0L, 255L));
}

/// The same with the sensor's headroom: radiance past the white keeps rising before the noise, so
/// an overexposed patch clips to a flat 255 as a real sensor's does (KITTI's sky).
inline std::uint8_t toByteClipping(const GammaTable& gamma, float linear, float noise) {
  const float level = linear * kExposure > 1.f ? 255.f * std::pow(linear * kExposure, 1.f / 2.2f) : gamma(linear);
  return static_cast<std::uint8_t>(std::clamp(roundHalfAway(level + noise), 0L, 255L));
}

/// The rays of a camera's image: each pixel centre's, and ss x ss over the pixels on an edge.
struct PixelRays {
  const SceneSnapshot& scene;
  const CameraModel& cam;
  const SkyLook& look;
  int ss; ///< samples per pixel side on an edge
  V3 pixel_x, pixel_y; ///< a pixel's step in the world
  std::vector<Radiance> radiance; ///< of the pixel centres' rays, row-major
  std::vector<std::int32_t> surface; ///< the surface each centre's ray hit

  /// The ray through each pixel centre, its texture filtered over the whole pixel; its depth and
  /// object into the images given.
  void traceCentres(cv::Mat* depth, cv::Mat* objects) {
    const int W = cam.width;
    radiance.resize(static_cast<std::size_t>(W) * static_cast<std::size_t>(cam.height));
    surface.resize(radiance.size());
    cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range& range) {
      for (int v = range.start; v < range.end; ++v) {
        float* d = depth ? depth->ptr<float>(v) : nullptr;
        std::int32_t* o = objects ? objects->ptr<std::int32_t>(v) : nullptr;
        for (int u = 0; u < W; ++u) {
          const Ray ray{cam.center, cam.direction(static_cast<float>(u), static_cast<float>(v))};
          const Sample s = trace(scene, ray, pixel_x, pixel_y, look);
          const std::size_t i = index(u, v);
          radiance[i] = s.radiance;
          surface[i] = s.surface;
          if (d)
            d[u] = s.depth;
          if (o)
            o[u] = s.object;
        }
      }
    });
  }

  /// The pixel's radiance: its centre's, or on a geometric edge (a neighbour sees another
  /// surface) the mean of ss x ss samples.
  Radiance at(int u, int v) const {
    const std::size_t i = index(u, v);
    const std::int32_t k = surface[i];
    const auto W = static_cast<std::size_t>(cam.width);
    const bool edge = (u > 0 && surface[i - 1] != k) || (u + 1 < cam.width && surface[i + 1] != k) ||
                      (v > 0 && surface[i - W] != k) || (v + 1 < cam.height && surface[i + W] != k);
    return edge && ss > 1 ? supersample(u, v) : radiance[i];
  }

private:
  std::size_t index(int u, int v) const {
    return static_cast<std::size_t>(v) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(u);
  }

  Radiance supersample(int u, int v) const {
    const float inv_ss = 1.f / static_cast<float>(ss);
    const V3 sub_x = pixel_x * inv_ss, sub_y = pixel_y * inv_ss;
    Radiance r;
    for (int sy = 0; sy < ss; ++sy)
      for (int sx = 0; sx < ss; ++sx) {
        // Centres of an ss x ss grid over the pixel (pixel centre at integer u, v).
        const float pu = static_cast<float>(u) - 0.5f + (static_cast<float>(sx) + 0.5f) * inv_ss;
        const float pv = static_cast<float>(v) - 0.5f + (static_cast<float>(sy) + 0.5f) * inv_ss;
        const Radiance q = trace(scene, {cam.center, cam.direction(pu, pv)}, sub_x, sub_y, look).radiance;
        r.r += q.r;
        r.g += q.g;
        r.b += q.b;
      }
    const float w = inv_ss * inv_ss;
    return {r.r * w, r.g * w, r.b * w};
  }
};

} // namespace

CameraRenderer::CameraRenderer(const Calibration& calibration, const SyntheticConfig& config)
    : calibration_(calibration), config_(config) {
  calibration_.requireImageSize();
  config_.validate();
}

cv::Mat CameraRenderer::render(const SceneSnapshot& scene, int camera, const Eigen::Isometry3d& T_world_cam0,
                               std::uint64_t noise_key, cv::Mat* depth, cv::Mat* objects) const {
  const CameraModel cam = cameraModel(calibration_, camera, T_world_cam0);
  const int W = cam.width, H = cam.height;
  const bool color = camera >= 2;
  cv::Mat image(H, W, color ? CV_8UC3 : CV_8UC1);
  if (depth)
    depth->create(H, W, CV_32FC1);
  if (objects)
    objects->create(H, W, CV_32SC1);
  const float sigma = static_cast<float>(config_.image_noise_sigma);
  // The noise of pixel i, channel c: hashKey(seed, noise_key, camera, i, c).
  const HashPrefix image_key =
      HashPrefix(static_cast<std::uint64_t>(config_.seed)).then(noise_key).then(static_cast<std::uint64_t>(camera));
  static const GammaTable gamma;
  const SkyLook look{config_.sky == "kitti",
                     static_cast<std::uint32_t>(hashKey(static_cast<std::uint64_t>(config_.seed), 0x5c1e5ULL))};
  const auto byte = [&](float linear, float noise) {
    return look.kitti ? toByteClipping(gamma, linear, noise) : toByte(gamma, linear, noise);
  };
  PixelRays rays{scene, cam, look, config_.supersampling, cam.rotate(1.f / cam.fx, 0.f, 0.f),
                 cam.rotate(0.f, 1.f / cam.fy, 0.f), {}, {}};
  rays.traceCentres(depth, objects);
  // Then gamma, noise and quantization.
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      std::uint8_t* row = image.ptr<std::uint8_t>(v);
      for (int u = 0; u < W; ++u) {
        const Radiance r = rays.at(u, v);
        const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(W) + static_cast<std::size_t>(u);
        const HashPrefix pixel_key = image_key.then(static_cast<std::uint64_t>(i));
        auto noise = [&](std::uint64_t channel) {
          return sigma > 0.f ? sigma * gaussianFast(pixel_key.then(channel).value()) : 0.f;
        };
        if (color) {
          // OpenCV's BGR order.
          row[3 * u + 0] = byte(r.b, noise(0));
          row[3 * u + 1] = byte(r.g, noise(1));
          row[3 * u + 2] = byte(r.r, noise(2));
        } else {
          row[u] = byte(0.30f * r.r + 0.59f * r.g + 0.11f * r.b, noise(0));
        }
      }
    }
  });
  return image;
}

} // namespace msf::synthetic
