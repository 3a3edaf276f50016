// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// SGBM stereo per KITTI frame (odometry 04, frames 0-9 in turn, 1226 x 370, 2 threads),
// each with both engines side by side (stereo.engine: native = our AVX2 SemiGlobalMatcher,
// opencv = cv::StereoSGBM): the baseline docs/results.md quotes (3-way, 128 disparities, block 5), the
// same narrowed by the interpolated LiDAR depth (stereo.prior_search_range), and with the
// explicit left-right check. Times are of SgbmStereo::computeDisparity (matching,
// conversion, confidence); cpu_ms_all_threads is the process CPU time per frame (all threads).
// BM_MatcherOneCore: the matchers alone on one thread, 128 disparities (cv::StereoSGBM, and
// SemiGlobalMatcher with its AVX2, AVX-512 and portable kernels), 3-way, with five paths
// (MODE_SGBM, stereo.mode sgbm) and ground_3way (stereo.unguided_mode): per-core cost, steadier
// than wall time on a machine shared with other work. BM_Sgbm5WayLidarRange: the LiDAR-narrowed rows with five paths.
// Post-processing, side by side: the native rows again with OpenCV's serial speckle filter
// and distance transform (native_opencv_tail; setParallelPostFilterEnabled(false)), and
// BM_PostFilter, that tail alone (OpenCV's median, speckle filter, conversion to float,
// confidence) on the matcher's output of the 10 frames, with OpenCV's routines and ours.
//
//   bench_stereo [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
//   (MSF_KITTI_DIR overrides the compiled-in path of the KITTI sample)
#include "kitti_sample.h"

#include <msf/io/sequence.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/stereo/parallel_post_filter.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_stereo.h>
#include <msf/stereo/speckle_filter.h>
#include <msf/stereo/stereo_confidence.h>

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

namespace {

/// The grey pairs and the interpolated LiDAR depth (all rings) of frames 0-9.
struct Data {
  msf::Calibration calibration;
  std::vector<cv::Mat> left, right, prior;
  Data() {
    const msf::Sequence sequence = msf::bench::kittiSequence();
    calibration = sequence.calibration();
    msf::LidarProjector projector(calibration);
    msf::DepthInterpolator interpolator;
    for (std::size_t i = 0; i < msf::bench::kFrames && i < sequence.size(); ++i) {
      const msf::Frame f = sequence.load(i, false);
      left.push_back(f.left);
      right.push_back(f.right);
      cv::Mat sparse, dense;
      projector.projectToImage(*f.scan, sparse);
      interpolator.interpolate(sparse, dense);
      prior.push_back(dense);
    }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

/// `engine`: opencv, native, or native_opencv_tail (native with OpenCV's post-processing).
void run(benchmark::State& state, msf::SgbmConfig config, bool with_prior, const char* engine_row) {
  const Data& d = data();
  const std::string row = engine_row;
  const bool opencv_tail = row == "native_opencv_tail";
  const char* engine = opencv_tail ? "native" : engine_row;
  config.engine = engine;
  msf::setParallelPostFilterEnabled(!opencv_tail);
  msf::SgbmStereo stereo(config);
  stereo.setCalibration(d.calibration);
  std::size_t i = 0, valid = 0, pixels = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const std::size_t f = i++ % d.left.size();
    stereo.setInputImages(d.left[f], d.right[f]);
    stereo.setDepthPrior(with_prior ? d.prior[f] : cv::Mat());
    stereo.computeDisparity();
    valid += static_cast<std::size_t>(cv::countNonZero(stereo.getDisparity() > 0.f));
    pixels += stereo.getDisparity().total();
  }
  // CPU time of all threads per frame: on a machine shared with other work it stays close to
  // what the frame costs, where wall time does not.
  state.counters["cpu_ms_all_threads"] =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
  state.counters["disparities"] = stereo.getSearchedDisparities();
  state.counters["valid_share"] = pixels ? static_cast<double>(valid) / pixels : 0.0;
  msf::setParallelPostFilterEnabled(true);
  if (stereo.getEngineUsed() != engine)
    state.SkipWithError("the native engine needs AVX2; this row ran OpenCV");
}

/// The matcher's output of the 10 frames at 128 disparities with the 3x3 median only.
const std::vector<cv::Mat>& medianOnlyDisparities() {
  static const std::vector<cv::Mat> fixed = [] {
    const Data& d = data();
    std::vector<cv::Mat> out;
    for (std::size_t f = 0; f < d.left.size(); ++f) {
      cv::Mat disparity;
      cv::StereoSGBM::create(0, 128, 5, 200, 800, -1, 63, 10, 0, 2, cv::StereoSGBM::MODE_SGBM_3WAY)
          ->compute(d.left[f], d.right[f], disparity);
      out.push_back(disparity);
    }
    return out;
  }();
  return fixed;
}

void BM_PostFilter(benchmark::State& state, bool parallel) {
  const std::vector<cv::Mat>& input = medianOnlyDisparities();
  msf::setParallelPostFilterEnabled(parallel);
  cv::Mat median, speckle_buffer, disparity;
  std::size_t i = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const cv::Mat& raw = input[i++ % input.size()];
    cv::medianBlur(raw, median, 3);
    if (parallel)
      msf::filterSpecklesParallel(median, -16, 100, 32, speckle_buffer);
    else
      cv::filterSpeckles(median, -16, 100, 32, speckle_buffer);
    median.convertTo(disparity, CV_32F, 1.0 / 16);
    benchmark::DoNotOptimize(msf::stereoConfidence(disparity).data);
  }
  state.counters["cpu_ms_all_threads"] =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
  msf::setParallelPostFilterEnabled(true);
}

/// The defaults with `mode`.
msf::SgbmConfig inMode(const char* mode) {
  msf::SgbmConfig config;
  config.mode = mode;
  return config;
}

void BM_Sgbm3Way128(benchmark::State& state, const char* engine) { run(state, inMode("sgbm_3way"), false, engine); }

void BM_Sgbm3WayLidarRange(benchmark::State& state, const char* engine) {
  run(state, inMode("sgbm_3way"), true, engine);
}

void BM_Sgbm3WayLidarRangeLrCheck(benchmark::State& state, const char* engine) {
  msf::SgbmConfig config = inMode("sgbm_3way");
  config.left_right_check = true;
  run(state, config, true, engine);
}

void BM_Sgbm5WayLidarRange(benchmark::State& state, const char* engine) { run(state, inMode("sgbm"), true, engine); }

/// `kernel`: opencv (cv::StereoSGBM), or the native matcher's avx512, avx2 or portable kernel;
/// `paths`: sgbm_3way, sgbm (five paths, OpenCV's MODE_SGBM) or ground_3way (native only).
void BM_MatcherOneCore(benchmark::State& state, const char* kernel, const char* paths) {
  const Data& d = data();
  const std::string name = kernel, mode = paths;
  const msf::SgbmConfig config;
  msf::SemiGlobalMatcher::Params params;
  params.num_disparities = config.num_disparities_px;
  params.p1 = config.resolvedP1();
  params.p2 = config.resolvedP2();
  params.diagonal_paths = mode == "sgbm";
  params.p1_rise = mode == "ground_3way" ? config.resolvedP1Rise() : 0;
  msf::SemiGlobalMatcher native(params);
  const cv::Ptr<cv::StereoSGBM> opencv = cv::StereoSGBM::create(
      0, params.num_disparities, params.block_size, params.p1, params.p2, params.disp12_max_diff,
      params.pre_filter_cap, params.uniqueness_ratio, params.speckle_window_size, params.speckle_range,
      mode == "sgbm" ? cv::StereoSGBM::MODE_SGBM : cv::StereoSGBM::MODE_SGBM_3WAY);
  if ((name == "avx2" || name == "avx512") && !msf::SemiGlobalMatcher::usesAvx2()) {
    state.SkipWithError("this CPU has no AVX2");
    return;
  }
  if (name == "avx512" && !msf::SemiGlobalMatcher::usesAvx512()) {
    state.SkipWithError("this CPU has no AVX-512BW");
    return;
  }
  msf::SemiGlobalMatcher::setAvx2Enabled(name != "portable");
  msf::SemiGlobalMatcher::setAvx512Enabled(name == "avx512");
  const msf::bench::OneThread one_thread;
  cv::Mat disparity;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.left.size();
    if (name == "opencv")
      opencv->compute(d.left[f], d.right[f], disparity);
    else
      native.compute(d.left[f], d.right[f], disparity);
  }
  msf::SemiGlobalMatcher::setAvx2Enabled(true);
  msf::SemiGlobalMatcher::setAvx512Enabled(true);
}

} // namespace

// The matchers alone, one thread, 128 disparities: OpenCV's 3-way and five paths, the native
// kernels for each, and ground_3way (the default without guidance).
#define MSF_MATCHER_ONE_CORE(row, kernel, paths)                                                                       \
  BENCHMARK_CAPTURE(BM_MatcherOneCore, row, kernel, paths)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10)
MSF_MATCHER_ONE_CORE(opencv, "opencv", "sgbm_3way");
MSF_MATCHER_ONE_CORE(avx2, "avx2", "sgbm_3way");
MSF_MATCHER_ONE_CORE(avx512, "avx512", "sgbm_3way");
MSF_MATCHER_ONE_CORE(portable, "portable", "sgbm_3way");
MSF_MATCHER_ONE_CORE(opencv_5paths, "opencv", "sgbm");
MSF_MATCHER_ONE_CORE(avx2_5paths, "avx2", "sgbm");
MSF_MATCHER_ONE_CORE(avx512_5paths, "avx512", "sgbm");
MSF_MATCHER_ONE_CORE(avx2_ground_3way, "avx2", "ground_3way");
MSF_MATCHER_ONE_CORE(avx512_ground_3way, "avx512", "ground_3way");
MSF_MATCHER_ONE_CORE(portable_ground_3way, "portable", "ground_3way");

// Each case's engines one after the other, so that both see the same machine load.
BENCHMARK_CAPTURE(BM_Sgbm3Way128, opencv, "opencv")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3Way128, native, "native")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3Way128, native_opencv_tail, "native_opencv_tail")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3WayLidarRange, opencv, "opencv")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3WayLidarRange, native, "native")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3WayLidarRange, native_opencv_tail, "native_opencv_tail")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm5WayLidarRange, opencv, "opencv")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm5WayLidarRange, native, "native")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3WayLidarRangeLrCheck, opencv, "opencv")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(10);
BENCHMARK_CAPTURE(BM_Sgbm3WayLidarRangeLrCheck, native, "native")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(10);

BENCHMARK_CAPTURE(BM_PostFilter, opencv, false)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(20);
BENCHMARK_CAPTURE(BM_PostFilter, parallel, true)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(20);

BENCHMARK_MAIN();
