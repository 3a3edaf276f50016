// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/fusion/facade_extension.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

namespace msf {

namespace {

/// A column's fit of inverse depth i = c + b v over its last run of anchors, each older row's
/// weight decayed by kDecay (about the nearest 5 rows count), with the run's grey, its last
/// anchor, and the stereo pixels above it that see a surface behind it.
struct ColumnFit {
  double sw = 0, sv = 0, svv = 0, si = 0, svi = 0;
  float grey = 0;            ///< the run's grey (a running mean)
  float last_inverse = 0;    ///< 1 / depth of the run's last anchor
  float anchor_weight = 0;
  int anchor_row = -1;       ///< row of the run's last anchor, -1: no run to go on from
  bool run_below = false;    ///< the row below was the run's: an anchor, or a pixel it reached
  int behind = 0;            ///< the last pixels with a depth, in a row, that lie behind the wall
  int gap = 0;               ///< rows of other image (a window) crossed since the wall's grey
  bool gap_seen = false;     ///< stereo in that gap saw the wall

  /// That many stereo pixels of a column in a row (no other depth between them), each more
  /// than kBehindSigmas of its sigmas behind the wall, see the surface above the wall's top
  /// edge (a building behind a lower one of the same grey, street 20: 12 sigmas): the column
  /// stops. SGBM's guesses on a blank wall come in runs too (its paths carry them), but
  /// nearer: at 3 sigmas they stopped columns on streets 4, 5 and 12 (fused D1 +0.3 points a
  /// frame), at 6 not.
  static constexpr int kBehindToStop = 3;
  static constexpr float kBehindSigmas = 6.f;

  static constexpr double kDecay = 0.8;

  void stop() { *this = ColumnFit(); }
  /// The line's slope b (only it is needed: the wall goes on at the run's mean inverse depth).
  bool slope(double& b) const {
    const double det = sw * svv - sv * sv;
    if (sw < 3.0 || !(std::abs(det) > 1e-9)) // fewer than 5 anchors in the run, or one row
      return false;
    b = (sw * svi - sv * si) / det;
    return true;
  }
  void add(int v, float z, float weight, float g) {
    const float inverse = 1.f / z;
    // A new run where the row below was not the run's, or where the depth jumps by more than
    // 5 % from the run's last anchor (an edge between two surfaces known that well).
    if (!run_below || std::abs(inverse - last_inverse) > 0.05f * inverse) {
      *this = ColumnFit();
      grey = g;
    } else {
      grey = 0.7f * grey + 0.3f * g;
    }
    sw = kDecay * sw + 1;
    sv = kDecay * sv + v;
    svv = kDecay * svv + static_cast<double>(v) * v;
    si = kDecay * si + inverse;
    svi = kDecay * svi + v * static_cast<double>(inverse);
    last_inverse = inverse;
    behind = 0;
    gap = 0;
    gap_seen = false;
    anchor_weight = weight;
    anchor_row = v;
    run_below = true;
  }
};

/// An overexposed pixel (a bright sky, a glare; 30 % of raw 0009's top rows) shows no surface,
/// however blank: a white wall's column stops there.
constexpr float kOverexposed = 250.f;

/// A window's glass lies up to ~0.2 m behind its façade: the wall's sigma there has this added
/// in quadrature.
constexpr float kWindowRecessSigma = 0.1f;

/// A pixel takes the wall's depth and weight (and free space weight): it had none, or SGBM's
/// guess on a blank surface.
void writeWall(float& z, float& w, float* f, float wall_depth, float wall_weight) {
  z = wall_depth;
  w = wall_weight;
  if (f)
    *f = w;
}

/// A pixel's own depth that agrees with the wall: two estimates of one depth, averaged by
/// inverse variance, the weights added (far stereo, sigma 1-3 m at 20-30 m, kept alone weighed
/// too little to be meshed).
void averageWithWall(float& z, float& w, float* f, float wall_depth, float wall_weight) {
  z = (z * w + wall_depth * wall_weight) / (w + wall_weight);
  w += wall_weight;
  if (f)
    *f = w;
}

void checkImage(const cv::Mat& image, int type, const cv::Size& size, const std::string& what) {
  if (image.type() != type || image.size() != size)
    throw InvalidInputError("facade extension: " + what + " is a " + std::to_string(image.cols) + "x" +
                            std::to_string(image.rows) + " image of type " + std::to_string(image.type()) +
                            ", expected type " + std::to_string(type) + " of " + std::to_string(size.width) + "x" +
                            std::to_string(size.height));
}

} // namespace

std::size_t extendFacades(const cv::Mat& left, const PinholeCamera& camera, const DepthFusionConfig& config,
                          cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight) {
  const cv::Size size = depth.size();
  checkImage(depth, CV_32FC1, size, "the depth");
  checkImage(left, CV_8UC1, size, "the grey image");
  checkImage(weight, CV_32FC1, size, "the weight");
  if (!free_space_weight.empty())
    checkImage(free_space_weight, CV_32FC1, size, "the free space weight");
  if (!camera.valid() || camera.width != size.width || camera.height != size.height)
    throw InvalidInputError("facade extension: the camera (" + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + ", fx " + std::to_string(camera.fx) +
                            ") does not fit the " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                            " depth");
  // The grey's mean and mean square over 5x5 pixels: a blank surface's variance is its noise's.
  cv::Mat mean, mean_square;
  cv::boxFilter(left, mean, CV_32F, cv::Size(5, 5));
  cv::sqrBoxFilter(left, mean_square, CV_32F, cv::Size(5, 5));
  const float anchor_weight = 1.f / (config.facade_anchor_sigma_m * config.facade_anchor_sigma_m);
  const float tolerance = config.facade_grey_tolerance;
  const float max_variance = config.facade_max_texture * config.facade_max_texture;
  std::atomic<std::size_t> extended{0};
  constexpr int kStrip = 128; // columns of one task, walked bottom-up together: rows stay contiguous
  parallelFor(cv::Range(0, (size.width + kStrip - 1) / kStrip), [&](const cv::Range& strips) {
    const int u0 = strips.start * kStrip, u1 = std::min(size.width, strips.end * kStrip);
    std::vector<ColumnFit> fits(static_cast<std::size_t>(u1 - u0));
    std::size_t count = 0;
    for (int v = size.height - 1; v >= 0; --v) {
      float* z = depth.ptr<float>(v);
      float* w = weight.ptr<float>(v);
      float* f = free_space_weight.empty() ? nullptr : free_space_weight.ptr<float>(v);
      const float* g = mean.ptr<float>(v);
      const float* g2 = mean_square.ptr<float>(v);
      const float y = (static_cast<float>(v) - camera.cy) / camera.fy;
      for (int u = u0; u < u1; ++u) {
        ColumnFit& fit = fits[static_cast<std::size_t>(u - u0)];
        const bool has_depth = z[u] > 0.f && std::isfinite(z[u]);
        const float grey_here = g[u];
        if (has_depth && w[u] >= anchor_weight) {
          fit.add(v, z[u], w[u], grey_here);
          continue;
        }
        fit.run_below = false;
        if (fit.anchor_row < 0)
          continue;
        const bool same_surface = std::abs(grey_here - fit.grey) <= tolerance &&
                                  g2[u] - grey_here * grey_here <= max_variance && grey_here < kOverexposed;
        double b;
        if ((!same_surface && config.facade_max_gap_m <= 0.f) || !fit.slope(b)) {
          fit.stop();
          continue;
        }
        // On a plane n . X = d, 1/z = n . ray / d, so d(1/z)/dv = n_y / (fy d) and, with
        // d <= |X| at the anchor, |n_y| <= |b| fy |X_anchor|: the slope tells a wall from the
        // road or a car's roof. The wall itself goes on vertical (n_y = 0): 1/z stays the run's
        // up the column. Its slope, from ~5 rows of anchors, carried 100 rows up put a façade
        // 0.3-1 m off (street 20, 0.077 -> 0.075 m with this alone).
        const double inverse = fit.si / fit.sw;
        const float x = (static_cast<float>(u) - camera.cx) / camera.fx;
        const double ray = std::sqrt(1.0 + x * x + y * y);
        if (!(inverse > 0.0) || std::abs(b) * camera.fy * ray > config.facade_max_normal_y * fit.last_inverse) {
          fit.stop();
          continue;
        }
        const float wall_depth = static_cast<float>(1.0 / inverse);
        auto sigmaAt = [&](int row) {
          const float height = static_cast<float>(fit.anchor_row - row) * wall_depth / camera.fy;
          return 1.f / std::sqrt(fit.anchor_weight) + config.facade_sigma_per_m * height;
        };
        const float sigma = sigmaAt(v);
        if (!same_surface) {
          // Another image on the wall (a window) is crossed up to facade_max_gap_m, while the
          // stereo there sees the wall and nothing else (a pole, a crown, the building behind a
          // roof's edge): written once the wall's grey comes back above it.
          if (++fit.gap * wall_depth > config.facade_max_gap_m * camera.fy) {
            fit.stop();
            continue;
          }
          if (has_depth) {
            const float own_sigma = w[u] > 0.f ? 1.f / std::sqrt(w[u]) : sigma;
            if (std::abs(z[u] - wall_depth) > 3.f * std::max(sigma, own_sigma)) {
              fit.stop();
              continue;
            }
            fit.gap_seen = true;
          }
          fit.run_below = true;
          continue;
        }
        if (fit.gap > 0) {
          if (!fit.gap_seen) {
            fit.stop(); // nothing says the wall goes on behind what was crossed (the sky)
            continue;
          }
          // The window is on the wall: its rows below take the wall, its stereo agreed with it.
          for (int r = v + 1; r <= v + fit.gap; ++r) {
            const float s = sigmaAt(r), window_weight = 1.f / (s * s + kWindowRecessSigma * kWindowRecessSigma);
            float& zr = depth.ptr<float>(r)[u];
            float* fr = f ? free_space_weight.ptr<float>(r) + u : nullptr;
            if (zr > 0.f && std::isfinite(zr)) {
              averageWithWall(zr, weight.ptr<float>(r)[u], fr, wall_depth, window_weight);
            } else {
              writeWall(zr, weight.ptr<float>(r)[u], fr, wall_depth, window_weight);
              ++count;
            }
          }
          fit.gap = 0;
          fit.gap_seen = false;
        }
        if (has_depth) {
          const float own_sigma = w[u] > 0.f ? 1.f / std::sqrt(w[u]) : sigma;
          if (std::abs(z[u] - wall_depth) <= 3.f * std::max(sigma, own_sigma)) {
            averageWithWall(z[u], w[u], f ? f + u : nullptr, wall_depth, 1.f / (sigma * sigma));
            fit.run_below = true;
            fit.behind = 0;
            continue;
          }
          if (z[u] - wall_depth > ColumnFit::kBehindSigmas * own_sigma) {
            if (++fit.behind >= ColumnFit::kBehindToStop) {
              fit.stop();
              continue; // the wall ended below: what stereo sees behind it stays
            }
          } else {
            fit.behind = 0;
          }
        }
        writeWall(z[u], w[u], f ? f + u : nullptr, wall_depth, 1.f / (sigma * sigma));
        fit.run_below = true;
        ++count;
      }
    }
    extended += count;
  });
  return extended;
}

std::size_t extendFacades(const cv::Mat& left, const Calibration& calibration, const DepthFusionConfig& config,
                          cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight) {
  Calibration at_depth_size = calibration;
  at_depth_size.image_size = depth.size();
  return extendFacades(left, PinholeCamera::fromCalibration(at_depth_size, 0), config, depth, weight,
                       free_space_weight);
}

} // namespace msf
