// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "semi_global_kernel.h"

#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/parallel_post_filter.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/speckle_filter.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace msf {

namespace {
// Fixed, like OpenCV's, so that results do not depend on the number of threads; 4 strips
// balance 2 threads on a shared machine for a few warm-up rows each.
constexpr int kStrips = 4;

std::atomic<bool> avx2_enabled{true};
std::atomic<bool> avx512_enabled{true};

[[noreturn]] void bad(const std::string& name, const std::string& why) {
  throw ConfigError("SemiGlobalMatcher: parameter '" + name + "' " + why);
}
} // namespace

bool SemiGlobalMatcher::usesAvx2() {
  static const bool cpu_has_avx2 = detail::sgmAvx2Available();
  return cpu_has_avx2 && avx2_enabled.load();
}

void SemiGlobalMatcher::setAvx2Enabled(bool enabled) { avx2_enabled.store(enabled); }

bool SemiGlobalMatcher::usesAvx512() {
  static const bool cpu_has_avx512 = detail::sgmAvx512Available();
  return usesAvx2() && cpu_has_avx512 && avx512_enabled.load();
}

void SemiGlobalMatcher::setAvx512Enabled(bool enabled) { avx512_enabled.store(enabled); }

int SemiGlobalMatcher::maxWidth() { return detail::kSgmMaxWidth; }

void SemiGlobalMatcher::setParams(const Params& params) {
  if (params.num_disparities <= 0 || params.num_disparities % 16 != 0)
    bad("num_disparities", "must be a positive multiple of 16, not " + std::to_string(params.num_disparities));
  if (params.block_size < 1 || params.block_size > 11 || params.block_size % 2 == 0)
    bad("block_size", "must be odd and in 1..11, not " + std::to_string(params.block_size));
  if (params.p1 <= 0 || params.p2 <= params.p1)
    bad("p2", "must be greater than p1 > 0 (p1 " + std::to_string(params.p1) + ", p2 " + std::to_string(params.p2) +
                  ")");
  if (params.p2 > 0x7FFF)
    bad("p2", "must be at most 32767, not " + std::to_string(params.p2));
  if (params.p1_rise < 0 || params.p1_rise >= params.p2)
    bad("p1_rise", "must be in 0..p2 - 1 (0: p1), not " + std::to_string(params.p1_rise));
  if (params.pre_filter_cap < 1 || params.pre_filter_cap > 63)
    bad("pre_filter_cap", "must be in 1..63, not " + std::to_string(params.pre_filter_cap));
  if (params.uniqueness_ratio < 0 || params.uniqueness_ratio > 100)
    bad("uniqueness_ratio", "must be in 0..100, not " + std::to_string(params.uniqueness_ratio));
  if (params.speckle_window_size < 0 || params.speckle_range < 0)
    bad("speckle_window_size", "and speckle_range must be >= 0");
  if (params.guidance_gain < 0 || params.guidance_gain > kMaxGuidanceGain)
    bad("guidance_gain", "must be in 0.." + std::to_string(kMaxGuidanceGain) + ", not " +
                             std::to_string(params.guidance_gain));
  if (params.guidance_max_penalty < 0 || params.guidance_max_penalty > kMaxGuidancePenalty)
    bad("guidance_max_penalty", "must be in 0.." + std::to_string(kMaxGuidancePenalty) + ", not " +
                                    std::to_string(params.guidance_max_penalty));
  params_ = params;
}

int SemiGlobalMatcher::maxGuidedDisparity() { return 2000; }

void SemiGlobalMatcher::compute(const cv::Mat& left, const cv::Mat& right, cv::Mat& disparity) {
  compute(left, right, disparity, cv::Mat());
}

namespace {

void checkInputs(const cv::Mat& left, const cv::Mat& right, const cv::Mat& guidance,
                 const SemiGlobalMatcher::Params& p) {
  if (left.empty() || right.empty())
    throw InvalidInputError(std::string("SemiGlobalMatcher: the ") + (left.empty() ? "left" : "right") +
                            " image is empty");
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1)
    throw InvalidInputError("SemiGlobalMatcher: the images must be 8-bit grey (CV_8UC1)");
  if (left.size() != right.size())
    throw InvalidInputError("SemiGlobalMatcher: the left image is " + std::to_string(left.cols) + "x" +
                            std::to_string(left.rows) + " but the right image is " + std::to_string(right.cols) + "x" +
                            std::to_string(right.rows));
  if (left.cols > SemiGlobalMatcher::maxWidth())
    throw InvalidInputError("SemiGlobalMatcher: the images are " + std::to_string(left.cols) +
                            " px wide, more than the " + std::to_string(SemiGlobalMatcher::maxWidth()) + " it matches");
  if (guidance.empty())
    return;
  if (guidance.type() != CV_16SC1 || guidance.size() != left.size())
    throw InvalidInputError("SemiGlobalMatcher: the guidance must be CV_16SC1 (disparity x 16) of the images' size " +
                            std::to_string(left.cols) + "x" + std::to_string(left.rows) + ", got " +
                            std::to_string(guidance.cols) + "x" + std::to_string(guidance.rows) + " of type " +
                            std::to_string(guidance.type()));
  const int max_guided = SemiGlobalMatcher::maxGuidedDisparity();
  if (p.min_disparity < -max_guided || p.min_disparity + p.num_disparities > max_guided)
    throw InvalidInputError("SemiGlobalMatcher: guidance handles disparities within +-" + std::to_string(max_guided) +
                            ", not " + std::to_string(p.min_disparity) + ".." +
                            std::to_string(p.min_disparity + p.num_disparities));
}

/// What every strip shares: the images, the parameters as the kernel takes them, the output
/// `raw` (CV_16S disparity x 16 of the images' size).
detail::SgmStrip stripJob(const cv::Mat& left, const cv::Mat& right, const cv::Mat& guidance,
                          const SemiGlobalMatcher::Params& p, cv::Mat& raw) {
  detail::SgmStrip job;
  job.left = left.ptr<std::uint8_t>();
  job.right = right.ptr<std::uint8_t>();
  job.left_step = left.step[0];
  job.right_step = right.step[0];
  job.width = left.cols;
  job.height = left.rows;
  job.min_disparity = p.min_disparity;
  job.num_disparities = p.num_disparities;
  job.block_radius = p.block_size / 2;
  job.p1 = p.p1;
  job.p2 = p.p2;
  job.p1_rise = p.p1_rise > 0 ? p.p1_rise : p.p1;
  job.prefilter_cap = std::max(p.pre_filter_cap, 15) | 1;
  job.uniqueness_ratio = p.uniqueness_ratio;
  job.disp12_max_diff = p.disp12_max_diff > 0 ? p.disp12_max_diff : 1; // as OpenCV 4.6: never off
  job.diagonal_paths = p.diagonal_paths;
  if (!guidance.empty()) {
    job.guidance = guidance.ptr<std::int16_t>();
    job.guidance_step = guidance.step[0] / sizeof(std::int16_t);
    job.guidance_gain = p.guidance_gain;
    job.guidance_max_penalty = p.guidance_max_penalty;
  }
  job.disparity = raw.ptr<std::int16_t>();
  job.disparity_step = raw.step[0] / sizeof(std::int16_t);
  return job;
}

using SgmKernel = void (*)(const detail::SgmStrip&);

SgmKernel chooseKernel(int num_disparities) {
  // AVX-512 where the disparities fill whole 32-lane vectors; with 16 left over its padding
  // lanes cost as much as it saves.
  return !SemiGlobalMatcher::usesAvx2()                                  ? detail::sgmStripPortable
         : SemiGlobalMatcher::usesAvx512() && num_disparities % 32 == 0 ? detail::sgmStripAvx512
                                                                          : detail::sgmStripAvx2;
}

/// Runs `job` in kStrips row strips in parallel, each warmed up over the rows above it, with a
/// workspace each.
void matchInStrips(const detail::SgmStrip& job, SgmKernel kernel, std::vector<std::vector<std::uint8_t>>& workspaces) {
  const int height = job.height;
  const int strips = std::min(kStrips, height);
  const int strip_rows = (height + strips - 1) / strips;
  // OpenCV's warm-up: the block's half height plus a tenth of a strip.
  const int overlap = job.block_radius + 1 + static_cast<int>(std::ceil(0.1 * strip_rows));
  const std::size_t workspace_bytes = detail::sgmWorkspaceBytes(job.width, job.min_disparity, job.num_disparities,
                                                                job.block_radius, job.diagonal_paths);
  workspaces.resize(static_cast<std::size_t>(strips));
  for (auto& workspace : workspaces)
    if (workspace.size() < workspace_bytes)
      workspace.resize(workspace_bytes);
  parallelFor(
      cv::Range(0, strips),
      [&](const cv::Range& range) {
        for (int i = range.start; i < range.end; ++i) {
          detail::SgmStrip strip = job;
          strip.row_output_begin = std::min(i * strip_rows, height);
          strip.row_end = std::min((i + 1) * strip_rows, height);
          strip.row_begin = std::max(strip.row_output_begin - overlap, 0);
          strip.workspace = workspaces[static_cast<std::size_t>(i)].data();
          if (strip.row_output_begin < strip.row_end)
            kernel(strip);
        }
      },
      strips);
}

/// As OpenCV's StereoSGBM::compute: a 3x3 median, then the speckle filter. OpenCV's median
/// is faster, per core and in wall time, than a vectorised copy of ours was on row bands in
/// parallel; our speckle filter runs on row bands in parallel with the same result (OpenCV's
/// is serial).
void postFilter(const cv::Mat& raw, const SemiGlobalMatcher::Params& p, cv::Mat& disparity,
                cv::Mat& speckle_buffer) {
  const int none = (p.min_disparity - 1) * 16;
  cv::medianBlur(raw, disparity, 3);
  if (p.speckle_window_size > 0) {
    if (parallelPostFilterEnabled())
      filterSpecklesParallel(disparity, none, p.speckle_window_size, 16 * p.speckle_range, speckle_buffer);
    else
      cv::filterSpeckles(disparity, none, p.speckle_window_size, 16 * p.speckle_range, speckle_buffer);
  }
}

} // namespace

void SemiGlobalMatcher::compute(const cv::Mat& left, const cv::Mat& right, cv::Mat& disparity,
                                const cv::Mat& guidance) {
  checkInputs(left, right, guidance, params_);
  raw_.create(left.size(), CV_16SC1);
  const detail::SgmStrip job = stripJob(left, right, guidance, params_, raw_);
  matchInStrips(job, chooseKernel(params_.num_disparities), workspaces_);
  postFilter(raw_, params_, disparity, speckle_buffer_);
}

} // namespace msf
