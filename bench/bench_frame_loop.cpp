// The frame loop a door drives on its caller's thread (the Python module's Pipeline.add_frame):
// KITTI odometry 04 frames 0-9, one frame after the other, each through Pipeline::computeDepth
// and Pipeline::integrate, into a fresh Pipeline per iteration, with the default configuration.
// bench/bench_python.py runs it beside the same loop through the Python module.
//
//   bench_frame_loop [--benchmark_format=json]   (MSF_KITTI_DIR overrides the sample's path)
//
// BM_LoadAndAddFrame: each frame read by Sequence::load, then added. BM_AddFrame: the frames
// read before the timing, then added. Each runs the 10 frames once untimed first, so that the
// process's first allocations and thread pool are not counted (the Python side runs warm too). Times per iteration are for the 10 frames: wall time, and
// the process's CPU time (all its threads), which a machine shared with other work disturbs less.
#include "kitti_sample.h"

#include <msf/pipeline/pipeline.h>
#include <msf/pipeline/pipeline_config.h>

#include <benchmark/benchmark.h>

#include <vector>

using namespace msf;

namespace {

void addFrame(Pipeline& pipeline, const Frame& frame) {
  FrameResult result = pipeline.computeDepth(frame);
  pipeline.integrate(result);
  benchmark::DoNotOptimize(result.fused.depth.data);
}

void loadAndAddFrames(const Sequence& sequence) {
  Pipeline pipeline(sequence.calibration(), PipelineConfig());
  for (std::size_t i = 0; i < msf::bench::kFrames; ++i)
    addFrame(pipeline, sequence.load(i));
}

void addFrames(const Sequence& sequence, const std::vector<Frame>& frames) {
  Pipeline pipeline(sequence.calibration(), PipelineConfig());
  for (const Frame& frame : frames)
    addFrame(pipeline, frame);
}

void BM_LoadAndAddFrame(benchmark::State& state) {
  const Sequence sequence = msf::bench::kittiSequence();
  loadAndAddFrames(sequence); // warm-up
  for (auto _ : state)
    loadAndAddFrames(sequence);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(msf::bench::kFrames));
}
BENCHMARK(BM_LoadAndAddFrame)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_AddFrame(benchmark::State& state) {
  const Sequence sequence = msf::bench::kittiSequence();
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < msf::bench::kFrames; ++i)
    frames.push_back(sequence.load(i));
  addFrames(sequence, frames); // warm-up
  for (auto _ : state)
    addFrames(sequence, frames);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
}
BENCHMARK(BM_AddFrame)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
