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
  /// than kBehindSigmas of its sigmas behind the wall in inverse depth (stereo's error is even
  /// in disparity: 1/w - 1/z > k sigma / z^2, that is z - w > k sigma w / z), see the surface
  /// above the wall's top edge (a building behind a lower one of the same grey): the column
  /// stops. SGBM's guesses on a blank wall come in runs too (its paths carry them), but
  /// nearer, hence the wide margin.
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

/// An overexposed pixel (a bright sky, a glare) shows no surface, however blank: a white wall's
/// column stops there.
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

/// Walks the columns of a depth image bottom-up and carries each column's wall up over the blank
/// pixels of the wall's grey (extendFacades).
class FacadeWalk {
public:
  FacadeWalk(const cv::Mat& left, const PinholeCamera& camera, const DepthFusionConfig& config, cv::Mat& depth,
             cv::Mat& weight, cv::Mat& free_space_weight)
      : camera_(camera), config_(config), depth_(depth), weight_(weight), free_(free_space_weight),
        anchor_weight_(1.f / (config.facade_anchor_sigma_m * config.facade_anchor_sigma_m)),
        max_variance_(config.facade_max_texture * config.facade_max_texture) {
    // The grey's mean and mean square over 5x5 pixels: a blank surface's variance is its noise's.
    cv::boxFilter(left, mean_, CV_32F, cv::Size(5, 5));
    cv::sqrBoxFilter(left, mean_square_, CV_32F, cv::Size(5, 5));
  }

  /// Columns [u0, u1), walked bottom-up together so that rows stay contiguous; the number of
  /// pixels that took a wall's depth.
  std::size_t walkStrip(int u0, int u1) const {
    std::vector<ColumnFit> fits(static_cast<std::size_t>(u1 - u0));
    std::size_t count = 0;
    for (int v = depth_.rows - 1; v >= 0; --v)
      for (int u = u0; u < u1; ++u)
        count += visit(fits[static_cast<std::size_t>(u - u0)], u, v);
    return count;
  }

private:
  /// One pixel of a column: an anchor goes into the fit, a pixel of the wall's grey takes its
  /// depth, another image on the wall (a window) is crossed.
  std::size_t visit(ColumnFit& fit, int u, int v) const {
    float& z = depth_.ptr<float>(v)[u];
    float& w = weight_.ptr<float>(v)[u];
    const bool has_depth = z > 0.f && std::isfinite(z);
    const float grey = mean_.ptr<float>(v)[u];
    if (has_depth && w >= anchor_weight_) {
      fit.add(v, z, w, grey);
      return 0;
    }
    fit.run_below = false;
    if (fit.anchor_row < 0)
      return 0;
    const float variance = mean_square_.ptr<float>(v)[u] - grey * grey;
    const bool same_surface = std::abs(grey - fit.grey) <= config_.facade_grey_tolerance &&
                              variance <= max_variance_ && grey < kOverexposed;
    float wall_depth;
    if ((!same_surface && config_.facade_max_gap_m <= 0.f) || !wallDepth(fit, u, v, wall_depth)) {
      fit.stop();
      return 0;
    }
    const float sigma = sigmaAt(fit, v, wall_depth);
    if (!same_surface) {
      crossGap(fit, has_depth ? z : 0.f, w, wall_depth, sigma);
      return 0;
    }
    std::size_t count = 0;
    if (fit.gap > 0) {
      if (!fit.gap_seen) {
        fit.stop(); // nothing says the wall goes on behind what was crossed (the sky)
        return 0;
      }
      count += fillWindow(fit, u, v, wall_depth);
    }
    return count + extendWall(fit, u, v, wall_depth, sigma);
  }

  /// The wall's depth at pixel (u, v), false when the column's fit says it is no wall. On a
  /// plane n . X = d, 1/z = n . ray / d, so d(1/z)/dv = n_y / (fy d) and, with d <= |X| at the
  /// anchor, |n_y| <= |b| fy |X_anchor|: the slope tells a wall from the road or a car's roof.
  /// The wall itself goes on vertical (n_y = 0): 1/z stays the run's up the column, since its
  /// slope, from a few rows of anchors, carried far up puts a façade off.
  bool wallDepth(const ColumnFit& fit, int u, int v, float& wall_depth) const {
    double b;
    if (!fit.slope(b))
      return false;
    const double inverse = fit.si / fit.sw;
    const float x = (static_cast<float>(u) - camera_.cx) / camera_.fx;
    const float y = (static_cast<float>(v) - camera_.cy) / camera_.fy;
    const double ray = std::sqrt(1.0 + x * x + y * y);
    if (!(inverse > 0.0) || std::abs(b) * camera_.fy * ray > config_.facade_max_normal_y * fit.last_inverse)
      return false;
    wall_depth = static_cast<float>(1.0 / inverse);
    return true;
  }

  /// The wall's sigma at `row`: the anchor's, growing with the height above it.
  float sigmaAt(const ColumnFit& fit, int row, float wall_depth) const {
    const float height = static_cast<float>(fit.anchor_row - row) * wall_depth / camera_.fy;
    return 1.f / std::sqrt(fit.anchor_weight) + config_.facade_sigma_per_m * height;
  }

  /// Another image on the wall (a window) is crossed up to facade_max_gap_m, while the stereo
  /// there (`z`, 0 for none) sees the wall and nothing else (a pole, a crown, the building
  /// behind a roof's edge): written once the wall's grey comes back above it.
  void crossGap(ColumnFit& fit, float z, float w, float wall_depth, float sigma) const {
    if (++fit.gap * wall_depth > config_.facade_max_gap_m * camera_.fy) {
      fit.stop();
      return;
    }
    if (z > 0.f) {
      const float own_sigma = w > 0.f ? 1.f / std::sqrt(w) : sigma;
      if (std::abs(z - wall_depth) > 3.f * std::max(sigma, own_sigma)) {
        fit.stop();
        return;
      }
      fit.gap_seen = true;
    }
    fit.run_below = true;
  }

  /// The window is on the wall: its rows below (u, v) take the wall, its stereo agreed with it.
  std::size_t fillWindow(ColumnFit& fit, int u, int v, float wall_depth) const {
    std::size_t count = 0;
    for (int r = v + 1; r <= v + fit.gap; ++r) {
      const float s = sigmaAt(fit, r, wall_depth);
      const float window_weight = 1.f / (s * s + kWindowRecessSigma * kWindowRecessSigma);
      float& zr = depth_.ptr<float>(r)[u];
      float* fr = free_.empty() ? nullptr : free_.ptr<float>(r) + u;
      if (zr > 0.f && std::isfinite(zr)) {
        averageWithWall(zr, weight_.ptr<float>(r)[u], fr, wall_depth, window_weight);
      } else {
        writeWall(zr, weight_.ptr<float>(r)[u], fr, wall_depth, window_weight);
        ++count;
      }
    }
    fit.gap = 0;
    fit.gap_seen = false;
    return count;
  }

  /// Pixel (u, v) of the wall's grey: its own depth that agrees is averaged with the wall, one
  /// behind it (the surface above the wall's top edge, seen over several pixels) stops the
  /// column, anything else takes the wall.
  std::size_t extendWall(ColumnFit& fit, int u, int v, float wall_depth, float sigma) const {
    float& z = depth_.ptr<float>(v)[u];
    float& w = weight_.ptr<float>(v)[u];
    float* f = free_.empty() ? nullptr : free_.ptr<float>(v) + u;
    if (z > 0.f && std::isfinite(z)) {
      const float own_sigma = w > 0.f ? 1.f / std::sqrt(w) : sigma;
      if (std::abs(z - wall_depth) <= 3.f * std::max(sigma, own_sigma)) {
        averageWithWall(z, w, f, wall_depth, 1.f / (sigma * sigma));
        fit.run_below = true;
        fit.behind = 0;
        return 0;
      }
      if (z - wall_depth > ColumnFit::kBehindSigmas * own_sigma * wall_depth / z) {
        if (++fit.behind >= ColumnFit::kBehindToStop) {
          fit.stop(); // the wall ended below: what stereo sees behind it stays
          return 0;
        }
      } else {
        fit.behind = 0;
      }
    }
    writeWall(z, w, f, wall_depth, 1.f / (sigma * sigma));
    fit.run_below = true;
    return 1;
  }

  const PinholeCamera& camera_;
  const DepthFusionConfig& config_;
  cv::Mat& depth_;
  cv::Mat& weight_;
  cv::Mat& free_;
  cv::Mat mean_, mean_square_;
  float anchor_weight_, max_variance_;
};

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
  const FacadeWalk walk(left, camera, config, depth, weight, free_space_weight);
  std::atomic<std::size_t> extended{0};
  constexpr int kStrip = 128; // columns of one task
  parallelFor(cv::Range(0, (size.width + kStrip - 1) / kStrip), [&](const cv::Range& strips) {
    extended += walk.walkStrip(strips.start * kStrip, std::min(size.width, strips.end * kStrip));
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
