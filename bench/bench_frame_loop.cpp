// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The frame loop a door drives on its caller's thread (the Python module's
// Reconstructor.add_frame): KITTI odometry 04 frames 0-9, one frame after the other through
// Reconstructor::addFrame (depth, the frame's pose, integration), into a fresh engine per
// iteration, with the default configuration. bench/bench_python.py runs it beside the same loop
// through the Python module.
//
//   bench_frame_loop [--benchmark_format=json]   (MSF_KITTI_DIR overrides the sample's path)
//
// BM_LoadAndAddFrame: each frame read by Sequence::load, then added. BM_AddFrame: the frames
// read before the timing, then added. BM_Run: the frames through run(), its stages overlapped.
// Each runs the 10 frames once untimed first, so that the process's first allocations and
// thread pool are not counted (the Python side runs warm too).
// Times per iteration are for the 10 frames: wall time, and the process's CPU time (all its
// threads), which a machine shared with other work disturbs less.
#include "kitti_sample.h"

#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/reconstructor.h>

#include <benchmark/benchmark.h>

#include <vector>

using namespace msf;

namespace {

void addFrame(Reconstructor& engine, const Frame& frame) {
  const FrameResult result = engine.addFrame(frame);
  benchmark::DoNotOptimize(result.fused.depth.data);
}

void loadAndAddFrames(const Sequence& sequence) {
  Reconstructor engine(sequence.calibration(), PipelineConfig());
  for (std::size_t i = 0; i < msf::bench::kFrames; ++i)
    addFrame(engine, sequence.load(i));
}

void addFrames(const Sequence& sequence, const std::vector<Frame>& frames) {
  Reconstructor engine(sequence.calibration(), PipelineConfig());
  for (const Frame& frame : frames)
    addFrame(engine, frame);
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

void runFrames(const Sequence& sequence, const std::vector<std::size_t>& indices) {
  Reconstructor engine(sequence.calibration(), PipelineConfig());
  engine.run(sequence, indices, nullptr);
}

// The same frames through run(), which overlaps loading, depth and integration on the
// engine's threads: the rate msf_reconstruct gets, beside the one-frame-per-call loop above.
void BM_Run(benchmark::State& state) {
  const Sequence sequence = msf::bench::kittiSequence();
  std::vector<std::size_t> indices(msf::bench::kFrames);
  for (std::size_t i = 0; i < indices.size(); ++i)
    indices[i] = i;
  runFrames(sequence, indices); // warm-up
  for (auto _ : state)
    runFrames(sequence, indices);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(indices.size()));
}
BENCHMARK(BM_Run)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
