// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Guided SGBM (stereo.guidance lidar) beside unguided, per KITTI frame (odometry 04, frames
// 0-9 in turn, 1226 x 370), both narrowed by the interpolated LiDAR as the pipeline does.
// BM_SgbmStereo: SgbmStereo::computeDisparity (the default five paths, hints from the sparse
// depth included), both threads; cpu_ms_all_threads is the process CPU time per frame,
// steadier than wall time on a shared machine. BM_MatcherOneCore: SemiGlobalMatcher alone
// (3-way) on one thread at 128 disparities, without and with the hints of the projected scan (bridged): the kernel's cost
// of the guidance. Unguided and guided rows alternate, so that both see the same load.
//
//   bench_guided_stereo [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
//   (MSF_KITTI_DIR overrides the compiled-in path of the KITTI sample)
#include "kitti_sample.h"

#include <msf/io/sequence.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/stereo/guidance_hints.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_stereo.h>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace {

/// The grey pairs, the projected scans and their compound interpolation, frames 0-9.
struct Data {
  msf::Calibration calibration;
  std::vector<cv::Mat> left, right, sparse, prior;
  Data() {
    const msf::Sequence sequence = msf::bench::kittiSequence();
    calibration = sequence.calibration();
    msf::LidarCompletion completion(calibration);
    for (std::size_t i = 0; i < msf::bench::kFrames && i < sequence.size(); ++i) {
      const msf::Frame f = sequence.load(i, false);
      left.push_back(f.left);
      right.push_back(f.right);
      cv::Mat projected, dense;
      completion.projector().projectToImage(*f.scan, projected);
      completion.computeDepth(*f.scan, dense);
      sparse.push_back(projected);
      prior.push_back(dense);
    }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

void BM_SgbmStereo(benchmark::State& state, const char* guidance) {
  const Data& d = data();
  msf::SgbmConfig config;
  config.guidance = guidance;
  msf::SgbmStereo stereo(config);
  stereo.setCalibration(d.calibration);
  std::size_t i = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const std::size_t f = i++ % d.left.size();
    stereo.setInputImages(d.left[f], d.right[f]);
    stereo.setDepthPrior(d.prior[f]);
    stereo.setGuidance(d.sparse[f]);
    stereo.computeDisparity();
  }
  state.counters["cpu_ms_all_threads"] =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
  if (stereo.getEngineUsed() != "native")
    state.SkipWithError("the native engine needs AVX2; this row ran OpenCV");
}

void BM_MatcherOneCore(benchmark::State& state, bool guided) {
  if (!msf::SemiGlobalMatcher::usesAvx2()) {
    state.SkipWithError("this CPU has no AVX2");
    return;
  }
  const Data& d = data();
  const msf::SgbmConfig config;
  msf::SemiGlobalMatcher::Params params;
  params.num_disparities = config.num_disparities_px;
  params.p1 = config.resolvedP1();
  params.p2 = config.resolvedP2();
  params.guidance_gain = config.guidance_gain;
  params.guidance_max_penalty = config.guidance_max_penalty;
  msf::SemiGlobalMatcher matcher(params);
  std::vector<cv::Mat> hints;
  for (const cv::Mat& sparse : d.sparse)
    hints.push_back(guided ? msf::guidanceHints(sparse, d.calibration.focalBaseline(), config.guidance_bridge_rows,
                                                config.guidance_bridge_agreement)
                           : cv::Mat());
  const msf::bench::OneThread one_thread;
  cv::Mat disparity;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.left.size();
    matcher.compute(d.left[f], d.right[f], disparity, hints[f]);
  }
}

} // namespace

BENCHMARK_CAPTURE(BM_MatcherOneCore, unguided, false)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_MatcherOneCore, guided, true)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(10);
BENCHMARK_CAPTURE(BM_SgbmStereo, none, "none")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(20);
BENCHMARK_CAPTURE(BM_SgbmStereo, lidar, "lidar")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(20);

BENCHMARK_MAIN();
