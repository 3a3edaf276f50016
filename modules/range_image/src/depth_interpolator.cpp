// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>
#include <msf/common/vector_clones.h>
#include <msf/range_image/depth_interpolator.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <vector>

namespace msf {

const char* toString(CombineRule rule) { return wordOf(kCombineRules, rule); }

void InterpolationConfig::validate() const {
  checkKeyRanges(*this);
  auto fail = [](const std::string& key, const std::string& rule) {
    throw ConfigError("interpolation." + key + " " + rule);
  };
  if (slice.short_gap_px > slice.max_gap_px)
    fail("short_gap_px", "must be 0..max_gap_px (" + std::to_string(slice.max_gap_px) + "), not " +
                             std::to_string(slice.short_gap_px));
  if (column_seed_gap_px > slice.max_gap_px)
    fail("column_seed_gap_px", "must be 0..max_gap_px (" + std::to_string(slice.max_gap_px) + "), not " +
                                   std::to_string(column_seed_gap_px));
  if (gaussian_size_px % 2 == 0)
    fail("gaussian_size_px", "must be odd, not " + std::to_string(gaussian_size_px));
}

DepthInterpolator::DepthInterpolator(const InterpolationConfig& config) { setConfig(config); }

void DepthInterpolator::setConfig(const InterpolationConfig& config) {
  config.validate();
  config_ = config;
}

namespace {

/// Adds w times one row of estimates to the vertical sums: values (empty pixels are 0) and weights.
MSF_VECTOR_CLONES void accumulateRow(const float* __restrict o, float w, float* __restrict v, float* __restrict m,
                                     int n) {
  for (int u = 0; u < n; ++u) {
    v[u] += w * o[u];
    m[u] += o[u] > 0.f ? w : 0.f;
  }
}

/// 1 where the hole fill must compute a value: no estimate, or (smooth) no sample.
MSF_VECTOR_CLONES void markTargets(const float* __restrict o, const float* __restrict d, bool smooth,
                                   std::uint8_t* __restrict mask, int n) {
  for (int u = 0; u < n; ++u)
    mask[u] = static_cast<std::uint8_t>((o[u] > 0.f ? 0 : 1) | (smooth && !(d[u] > 0.f) ? 1 : 0));
}

/// The first u in [from, n) with mask[u] != 0, else n; skips eight zero bytes at a time.
/// mask[n .. n + 7] must be 0.
inline int nextTarget(const std::uint8_t* mask, int from, int n) {
  int u = from;
  while (u < n && (u & 7))
    if (mask[u])
      return u;
    else
      ++u;
  while (u < n) {
    std::uint64_t word;
    std::memcpy(&word, mask + u, 8);
    if (word)
      break;
    u += 8;
  }
  while (u < n && !mask[u])
    ++u;
  return std::min(u, n);
}

/// One row: estimates into `out`, gap lengths into `gap` (0 on samples and holes).
/// Returns whether the row has a sample.
bool rowPass(const float* in, int n, const SliceParams& p, float* out, std::uint8_t* gap) {
  std::fill(out, out + n, 0.f);
  std::fill(gap, gap + n, std::uint8_t{0});
  int last = -1;
  float z_last = 0.f;
  for (int i = 0; i < n; ++i) {
    // Samples are a few percent of a row: skip runs of eight exact zeros at a time.
    if ((i & 7) == 0 && i + 8 <= n) {
      std::uint64_t words[4];
      std::memcpy(words, in + i, sizeof words);
      if ((words[0] | words[1] | words[2] | words[3]) == 0) {
        i += 7;
        continue;
      }
    }
    const float z = in[i];
    if (!(z > 0.f))
      continue;
    out[i] = z;
    const int empty = i - last - 1;
    if (last >= 0 && empty > 0 && empty <= p.max_gap_px && !isDepthJump(z_last, z, p)) {
      const std::uint8_t g = gapCode(empty);
      float* o = out + last;
      std::uint8_t* gp = gap + last;
      bridgeValues(z_last, z, empty, p, [&](int k, float value) {
        o[k] = value;
        gp[k] = g;
      });
    }
    last = i;
    z_last = z;
  }
  return last >= 0;
}

/// The estimate of a pixel that has a row estimate r (gap gr) and a column one c (gap gc).
inline float combine(float r, int gr, float c, int gc, CombineRule rule) {
  switch (rule) {
  case CombineRule::Average:
    return 0.5f * (r + c);
  case CombineRule::Nearest:
    return std::min(r, c);
  case CombineRule::GapWeighted: {
    const float wr = 1.f / static_cast<float>(1 + gr), wc = 1.f / static_cast<float>(1 + gc);
    return (wr * r + wc * c) / (wr + wc);
  }
  default:
    return gr < gc ? r : gc < gr ? c : 0.5f * (r + c);
  }
}

/// Columns [c0, c1), in place over the row pass's result. The seeds of a column are its
/// samples and the row estimates bridged over at most `seed_gap` pixels. The image is
/// swept row by row, so that reads are contiguous; a bridge writes back into the rows of
/// its gap (still in cache), merging with their row estimates: each pixel lies in at most
/// one gap of its column, and rows are read before any bridge reaches them.
void columnPass(int H, int W, int c0, int c1, const SliceParams& p, int seed_gap, CombineRule rule, float* out,
                const std::uint8_t* gap, int* last, float* z_last) {
  std::fill(last + c0, last + c1, -1);
  for (int r = 0; r < H; ++r) {
    const float* o = out + static_cast<std::ptrdiff_t>(r) * W;
    const std::uint8_t* g = gap + static_cast<std::ptrdiff_t>(r) * W;
    for (int c = c0; c < c1; ++c) {
      const float z = o[c];
      if (!(z > 0.f) || g[c] > seed_gap)
        continue;
      const int empty = r - last[c] - 1;
      if (last[c] >= 0 && empty > 0 && empty <= p.max_gap_px && !isDepthJump(z_last[c], z, p)) {
        const int gc = empty;
        float* column = out + static_cast<std::ptrdiff_t>(last[c]) * W + c;
        const std::uint8_t* row_gap = gap + static_cast<std::ptrdiff_t>(last[c]) * W + c;
        bridgeValues(z_last[c], z, empty, p, [&](int k, float value) {
          float& e = column[static_cast<std::ptrdiff_t>(k) * W];
          e = e > 0.f ? combine(e, row_gap[static_cast<std::ptrdiff_t>(k) * W], value, gc, rule) : value;
        });
      }
      last[c] = r;
      z_last[c] = z;
    }
  }
}

} // namespace

void DepthInterpolator::interpolate(const cv::Mat& depth, cv::Mat& out) {
  if (depth.type() != CV_32FC1 || depth.empty())
    throw InvalidInputError("interpolation: expected a non-empty CV_32FC1 depth image");
  if (out.data == depth.data)
    throw InvalidInputError("interpolation: the output may not be the input image");
  const int H = depth.rows, W = depth.cols;
  const double stripes = config_.threads > 0 ? config_.threads : -1; // at most that many threads at once
  const SliceParams& slice = config_.slice;
  out.create(H, W, CV_32FC1);
  row_gap_.create(H, W, CV_8UC1);
  last_.resize(static_cast<std::size_t>(W));
  z_last_.resize(static_cast<std::size_t>(W));
  row_has_.assign(static_cast<std::size_t>(H), 0);
  prepareHoleFill(W);

  // Slices are independent, so every pass splits them over OpenCV's pool and the result
  // does not depend on the number of threads.
  parallelFor(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r)
      row_has_[r] = rowPass(depth.ptr<float>(r), W, slice, out.ptr<float>(r), row_gap_.ptr<std::uint8_t>(r));
  }, stripes);
  // One band of columns per thread, of whole cache lines (16 floats).
  const int bands = config_.threads > 0 ? config_.threads : cv::getNumThreads();
  parallelFor(cv::Range(0, bands), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int c0 = std::min(W, (W * b / bands + 15) / 16 * 16);
      const int c1 = b + 1 == bands ? W : std::min(W, (W * (b + 1) / bands + 15) / 16 * 16);
      columnPass(H, W, c0, c1, slice, config_.column_seed_gap_px, config_.combine, out.ptr<float>(),
                 row_gap_.ptr<std::uint8_t>(), last_.data(), z_last_.data());
    }
  });
  if (config_.gaussian)
    fillHoles(depth, out, stripes);
}

void DepthInterpolator::prepareHoleFill(int width) {
  const int k = config_.gaussian_size_px / 2;
  kernel_.resize(static_cast<std::size_t>(2 * k + 1));
  const float s2 = config_.gaussian_sigma_px * config_.gaussian_sigma_px;
  float total = 0.f;
  for (int i = -k; i <= k; ++i)
    total += kernel_[i + k] = std::exp(-0.5f * static_cast<float>(i * i) / s2);
  for (float& w : kernel_)
    w /= total;
  values_.create(static_cast<int>(row_has_.size()), width + 2 * k, CV_32FC1);
  targets_.create(static_cast<int>(row_has_.size()), width + 8, CV_8UC1);
  weights_.create(static_cast<int>(row_has_.size()), width + 2 * k, CV_32FC1);
}

void DepthInterpolator::fillHoles(const cv::Mat& depth, cv::Mat& out, double stripes) {
  // Normalized convolution (Knutsson and Westin 1993): the Gaussian average of the
  // estimates around a hole, empty pixels weighing 0. Separable: a vectorized vertical
  // pass into rows padded by k zeros, around the holes only, then the horizontal pass at
  // the holes.
  // Rows beyond reach of any sample (the sky above the top ring) are skipped.
  const int H = out.rows, W = out.cols, k = config_.gaussian_size_px / 2;
  int first = H, last = -1;
  for (int r = 0; r < H; ++r)
    if (row_has_[r]) {
      first = std::min(first, r);
      last = r;
    }
  const int r0 = std::max(0, first - k), r1 = std::min(H - 1, last + k);
  if (r0 > r1)
    return; // no sample
  const float* g = kernel_.data();
  const float min_weight = config_.gaussian_min_weight;
  const bool smooth = config_.gaussian_smooth_valid;
  parallelFor(cv::Range(r0, r1 + 1), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      // The targets of this row (holes; with smooth_valid, every pixel but the samples), as
      // a byte mask made by a vectorized loop, then gathered into spans of targets +- k:
      // vertical sums are made only there (most of a row within the rings is estimated).
      std::uint8_t* mask = targets_.ptr<std::uint8_t>(r);
      markTargets(out.ptr<float>(r), depth.ptr<float>(r), smooth, mask, W);
      std::fill(mask + W, mask + W + 8, std::uint8_t{0}); // stops the word scan below
      float* v = values_.ptr<float>(r) + k;
      float* m = weights_.ptr<float>(r) + k;
      std::fill(v - k, v, 0.f); // the padding beyond the image's sides reads as empty
      std::fill(m - k, m, 0.f);
      std::fill(v + W, v + W + k, 0.f);
      std::fill(m + W, m + W + k, 0.f);
      int u = nextTarget(mask, 0, W);
      while (u < W) {
        const int a = std::max(0, u - k);
        int last_target = u, next = nextTarget(mask, u + 1, W);
        while (next < W && next <= last_target + 2 * k + 1) {
          last_target = next;
          next = nextTarget(mask, next + 1, W);
        }
        const int b = std::min(W, last_target + k + 1);
        std::fill(v + a, v + b, 0.f);
        std::fill(m + a, m + b, 0.f);
        for (int i = std::max(-k, -r); i <= std::min(k, H - 1 - r); ++i)
          accumulateRow(out.ptr<float>(r + i) + a, g[i + k], v + a, m + a, b - a);
        u = next;
      }
    }
  }, stripes);
  // Every vertical sum is made (the call above has returned) before any hole is written.
  parallelFor(cv::Range(r0, r1 + 1), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      // The horizontal pass at the targets only.
      const std::uint8_t* mask = targets_.ptr<std::uint8_t>(r);
      const float* v = values_.ptr<float>(r);
      const float* m = weights_.ptr<float>(r);
      float* o = out.ptr<float>(r);
      for (int u = nextTarget(mask, 0, W); u < W; u = nextTarget(mask, u + 1, W)) {
        float sv = 0.f, sm = 0.f;
        for (int i = 0; i <= 2 * k; ++i) {
          sv += g[i] * v[u + i];
          sm += g[i] * m[u + i];
        }
        if (sm >= min_weight)
          o[u] = sv / sm;
      }
    }
  }, stripes);
}

} // namespace msf
