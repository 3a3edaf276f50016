#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/range_image/depth_interpolator.h>

#include <opencv2/imgproc.hpp>
#include <pcl/console/print.h>

#include <omp.h>

#include <algorithm>

namespace msf {

CombineRule parseCombineRule(const std::string& name) {
  if (name == "average")
    return CombineRule::Average;
  if (name == "shorter_gap")
    return CombineRule::ShorterGap;
  if (name == "gap_weighted")
    return CombineRule::GapWeighted;
  if (name == "nearest")
    return CombineRule::Nearest;
  throw ConfigError("interpolation.combine '" + name + "' is not average, shorter_gap, gap_weighted or nearest");
}

const char* toString(CombineRule rule) {
  switch (rule) {
  case CombineRule::Average:
    return "average";
  case CombineRule::GapWeighted:
    return "gap_weighted";
  case CombineRule::Nearest:
    return "nearest";
  default:
    return "shorter_gap";
  }
}

void InterpolationConfig::print() const {
  pcl::console::print_info(
      "interpolation: %s, cubic gaps <= %d px, gaps <= %d px, edges: jump > %g m, > %g z, > %g / m in 1/z, "
      "%s depth, column seeds <= %d px, combine %s, "
      "gaussian %s (%d px, sigma %g, min weight %g%s)\n",
      toString(slice.interpolant), slice.short_gap_px, slice.max_gap_px, slice.jump_abs_m, slice.jump_rel,
      slice.jump_inv_per_m, slice.inverse_depth ? "inverse" : "plain", column_seed_gap_px, toString(combine), gaussian ? "on" : "off", gaussian_size_px,
      gaussian_sigma_px, gaussian_min_weight, gaussian_smooth_valid ? ", smooths estimates" : "");
}

void InterpolationConfig::read(const cv::FileNode& node) {
  std::string method = toString(slice.interpolant), rule = toString(combine);
  readKey(node, "method", method);
  slice.interpolant = parseSliceInterpolant(method);
  readKey(node, "short_gap_px", slice.short_gap_px);
  readKey(node, "max_gap_px", slice.max_gap_px);
  readKey(node, "jump_abs_m", slice.jump_abs_m);
  readKey(node, "jump_rel", slice.jump_rel);
  readKey(node, "cubic_alpha", slice.cubic_alpha);
  readKey(node, "cubic_beta", slice.cubic_beta);
  readKey(node, "inverse_depth", slice.inverse_depth);
  readKey(node, "jump_inv_per_m", slice.jump_inv_per_m);
  readKey(node, "column_seed_gap_px", column_seed_gap_px);
  readKey(node, "combine", rule);
  combine = parseCombineRule(rule);
  readKey(node, "gaussian", gaussian);
  readKey(node, "gaussian_size_px", gaussian_size_px);
  readKey(node, "gaussian_sigma_px", gaussian_sigma_px);
  readKey(node, "gaussian_min_weight", gaussian_min_weight);
  readKey(node, "gaussian_smooth_valid", gaussian_smooth_valid);
  readKey(node, "threads", threads);
  validate();
}

void InterpolationConfig::validate() const {
  auto fail = [](const std::string& key, const std::string& rule) {
    throw ConfigError("interpolation." + key + " " + rule);
  };
  if (slice.max_gap_px < 0)
    fail("max_gap_px", "must be >= 0, not " + std::to_string(slice.max_gap_px));
  if (slice.short_gap_px < 0 || slice.short_gap_px > slice.max_gap_px)
    fail("short_gap_px", "must be 0..max_gap_px (" + std::to_string(slice.max_gap_px) + "), not " +
                             std::to_string(slice.short_gap_px));
  if (!(slice.jump_abs_m >= 0.f))
    fail("jump_abs_m", "must be >= 0");
  if (!(slice.jump_rel >= 0.f))
    fail("jump_rel", "must be >= 0");
  if (!(slice.jump_inv_per_m >= 0.f))
    fail("jump_inv_per_m", "must be >= 0");
  if (column_seed_gap_px < 0 || column_seed_gap_px > slice.max_gap_px)
    fail("column_seed_gap_px", "must be 0..max_gap_px (" + std::to_string(slice.max_gap_px) + "), not " +
                                   std::to_string(column_seed_gap_px));
  if (!(gaussian_size_px >= 1 && gaussian_size_px % 2 == 1 && gaussian_size_px <= 31))
    fail("gaussian_size_px", "must be odd, 1..31, not " + std::to_string(gaussian_size_px));
  if (!(gaussian_sigma_px > 0.f))
    fail("gaussian_sigma_px", "must be > 0");
  if (!(gaussian_min_weight > 0.f && gaussian_min_weight <= 1.f))
    fail("gaussian_min_weight", "must be in (0, 1]");
  if (threads < 0)
    fail("threads", "must be >= 0");
}

DepthInterpolator::DepthInterpolator(const InterpolationConfig& config) { setConfig(config); }

void DepthInterpolator::setConfig(const InterpolationConfig& config) {
  config.validate();
  config_ = config;
}

namespace {

inline float combine(float r, std::uint8_t gr, float c, std::uint8_t gc, CombineRule rule) {
  if (!(r > 0.f))
    return c;
  if (!(c > 0.f))
    return r;
  switch (rule) {
  case CombineRule::Average:
    return 0.5f * (r + c);
  case CombineRule::Nearest:
    return std::min(r, c);
  case CombineRule::GapWeighted: {
    const float wr = 1.f / (1.f + gr), wc = 1.f / (1.f + gc);
    return (wr * r + wc * c) / (wr + wc);
  }
  default:
    return gr < gc ? r : gc < gr ? c : 0.5f * (r + c);
  }
}

} // namespace

void DepthInterpolator::interpolate(const cv::Mat& depth, cv::Mat& out) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("interpolation: expected a non-empty CV_32FC1 depth image");
  const int H = depth.rows, W = depth.cols;
  const int nthreads = config_.threads > 0 ? config_.threads : omp_get_max_threads();
  const SliceParams& slice = config_.slice;
  rows_.create(H, W, CV_32FC1);
  cols_.create(H, W, CV_32FC1);
  row_gap_.create(H, W, CV_8UC1);
  col_gap_.create(H, W, CV_8UC1);
  out.create(H, W, CV_32FC1);
  const int seed_gap = config_.column_seed_gap_px;
  if (seed_gap > 0)
    seeds_.create(H, W, CV_32FC1);

  // Every slice is independent: rows over threads, then columns in bands of whole cache lines.
  // One stride for the input, the estimates and the gaps of a column.
  const cv::Mat in = depth.isContinuous() ? depth : depth.clone();
#pragma omp parallel num_threads(nthreads)
  {
#pragma omp for schedule(static)
    for (int r = 0; r < H; ++r)
      interpolateSlice(in.ptr<float>(r), 1, W, slice, rows_.ptr<float>(r), row_gap_.ptr<std::uint8_t>(r));
    if (seed_gap > 0) {
#pragma omp for schedule(static)
      for (int r = 0; r < H; ++r) {
        const float* R = rows_.ptr<float>(r);
        const std::uint8_t* G = row_gap_.ptr<std::uint8_t>(r);
        float* s = seeds_.ptr<float>(r);
        for (int u = 0; u < W; ++u)
          s[u] = G[u] <= seed_gap ? R[u] : 0.f;
      }
    }
    const float* column_input = seed_gap > 0 ? seeds_.ptr<float>() : in.ptr<float>();
#pragma omp for schedule(static)
    for (int c0 = 0; c0 < W; c0 += 64)
      for (int c = c0; c < std::min(W, c0 + 64); ++c)
        interpolateSlice(column_input + c, W, H, slice, cols_.ptr<float>() + c, col_gap_.ptr<std::uint8_t>() + c);
#pragma omp for schedule(static)
    for (int r = 0; r < H; ++r) {
      const float* R = rows_.ptr<float>(r);
      const float* C = cols_.ptr<float>(r);
      const std::uint8_t* GR = row_gap_.ptr<std::uint8_t>(r);
      const std::uint8_t* GC = col_gap_.ptr<std::uint8_t>(r);
      float* o = out.ptr<float>(r);
      for (int u = 0; u < W; ++u)
        o[u] = combine(R[u], GR[u], C[u], GC[u], config_.combine);
    }
  }
  if (!config_.gaussian)
    return;

  // Normalized convolution: blur(values) / blur(mask) is the Gaussian average of the
  // estimates around a pixel, ignoring empty ones (Knutsson and Westin 1993).
  cv::Mat& mask = weights_;
  mask.create(H, W, CV_32FC1);
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int r = 0; r < H; ++r) {
    const float* o = out.ptr<float>(r);
    float* m = mask.ptr<float>(r);
    for (int u = 0; u < W; ++u)
      m[u] = o[u] > 0.f ? 1.f : 0.f;
  }
  const cv::Size kernel(config_.gaussian_size_px, config_.gaussian_size_px);
  const double sigma = config_.gaussian_sigma_px;
  cv::GaussianBlur(out, values_, kernel, sigma, sigma, cv::BORDER_CONSTANT);
  cv::GaussianBlur(mask, mask, kernel, sigma, sigma, cv::BORDER_CONSTANT);
  const float min_weight = config_.gaussian_min_weight;
  const bool smooth = config_.gaussian_smooth_valid;
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int r = 0; r < H; ++r) {
    const float* d = depth.ptr<float>(r);
    const float* b = values_.ptr<float>(r);
    const float* m = mask.ptr<float>(r);
    float* o = out.ptr<float>(r);
    for (int u = 0; u < W; ++u) {
      const bool hole = !(o[u] > 0.f);
      if ((hole || (smooth && !(d[u] > 0.f))) && m[u] >= min_weight)
        o[u] = b[u] / m[u];
    }
  }
}

} // namespace msf
