// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The synthetic street's frame (msf_synth): camera 0 (grey, with its depth and ids), camera 2
// (colour) and the LiDAR scan, at frames 100, 500 and 900 of a 1000-frame street in turn,
// single-threaded, CPU time. A 1000-frame drive renders two grey and two colour cameras and
// one scan per frame: its CPU time per frame is about 2 x (Grey + Colour) + Lidar.
//
//   bench_synth [--benchmark_filter=Grey]
#include <msf/synthetic/kitti_rig.h>
#include <msf/synthetic/synthetic_generator.h>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>

#include <cstddef>

namespace {

const msf::synthetic::SyntheticGenerator& generator() {
  static const msf::synthetic::SyntheticGenerator g([] {
    msf::synthetic::SyntheticConfig config;
    config.frames = 1000;
    return config;
  }());
  return g;
}

constexpr std::size_t kFrames[] = {100, 500, 900};

void camera(benchmark::State& state, int camera) {
  const auto& g = generator();
  cv::setNumThreads(1);
  std::size_t k = 0;
  cv::Mat depth, ids;
  for (auto _ : state) {
    const std::size_t i = kFrames[k++ % 3];
    const msf::synthetic::SceneSnapshot snapshot = g.sceneAt(i);
    const cv::Mat image = g.renderer().render(snapshot, camera, g.poses()[i], i, camera == 0 ? &depth : nullptr,
                                              camera == 0 ? &ids : nullptr);
    benchmark::DoNotOptimize(image.data);
  }
}

void lidar(benchmark::State& state) {
  const auto& g = generator();
  cv::setNumThreads(1);
  std::size_t k = 0, points = 0;
  for (auto _ : state) {
    const std::size_t i = kFrames[k++ % 3];
    const msf::synthetic::SceneSnapshot snapshot = g.sceneAt(i);
    points += g.lidar().scan(snapshot, g.poses()[i] * g.calibration().T_cam0_velo, i).size();
  }
  state.counters["points"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kAvgIterations);
}

} // namespace

BENCHMARK_CAPTURE(camera, Grey, 0)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(6);
BENCHMARK_CAPTURE(camera, Colour, 2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(6);
BENCHMARK(lidar)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(6);

BENCHMARK_MAIN();
