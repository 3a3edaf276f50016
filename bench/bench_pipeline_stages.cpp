// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The stages of msf_reconstruct on KITTI odometry 04 frames 0-9 with config/kitti.yaml, each
// alone on the pipeline's own input (the fused depth and the scans of Reconstructor::computeDepth,
// the dataset's poses), in process CPU time per frame: the figure that tells whether a change
// makes the whole pipeline cheaper, with less noise than msf_reconstruct's frame rate on a
// shared machine (bench/bench_pipeline.sh).
//
//   bench_pipeline_stages [--benchmark_repetitions=9]   (MSF_KITTI_DIR overrides the sample's
//                                                        path, MSF_CONFIG the configuration)
//
// BM_StageIntegrate: the 10 fused frames and each scan's free space into a fresh volume
// (Reconstructor::integrate's work: TsdfIntegrator::integrateFrame, the depth and the free space
// of the scan, the open sky and the rays beyond the range), per frame.
// BM_StageDepth: steps 1-4 of one frame (Reconstructor::computeDepth), per frame.
// BM_StageMapPrior: the map of the 10 frames rendered into each frame's holes (no fused depth,
// not open sky), as map_prior.enabled does after each frame is integrated (MapRaycaster), per frame.
// BM_StageOpenSky: protocol 6's open sky of each frame (SkyScoring::addFrame: the whole scan
// projected, SkyMask, the mask kept as runs), which msf_reconstruct's loading thread computes for
// every frame, per frame.
#include "kitti_sample.h"

#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/sky_scoring.h>
#include <msf/pipeline/source_depth_frame.h>
#include <msf/reconstruction/map_raycaster.h>

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

using namespace msf;

namespace {

std::string configPath() {
  const char* env = std::getenv("MSF_CONFIG");
  return env ? env : MSF_SOURCE_DIR "/config/kitti.yaml";
}

struct Data {
  Sequence sequence = msf::bench::kittiSequence();
  PipelineConfig config = PipelineConfig::load(configPath());
  std::unique_ptr<Reconstructor> pipeline;
  std::vector<FrameResult> results;
  std::vector<DepthFrame> frames;
  Data() {
    pipeline = std::make_unique<Reconstructor>(sequence.calibration(), config);
    for (std::size_t i = 0; i < msf::bench::kFrames; ++i) {
      FrameResult r = pipeline->computeDepth(sequence.load(i));
      frames.push_back(fusedDepthFrame(r, config.fusion, sequence.calibration().focalBaseline()));
      results.push_back(std::move(r));
    }
  }
};

Data& data() {
  static Data d;
  return d;
}

void BM_StageIntegrate(benchmark::State& state) {
  Data& d = data();
  double projected = 0, updated = 0, blocks = 0;
  for (auto _ : state) {
    TsdfVolume volume(d.config.volume.voxel_size_m, d.config.volume.truncation_m);
    TsdfIntegrator integrator(volume, d.config.integrator);
    projected = updated = 0;
    for (std::size_t i = 0; i < d.frames.size(); ++i) {
      integrator.integrateFrame(d.frames[i], d.results[i].T_world_cam0,
                                freeSpaceOf(d.results[i], d.results[i].fused.camera, d.config.fusion,
                                            d.sequence.calibration()));
      projected += static_cast<double>(integrator.lastStats().voxels_projected);
      updated += static_cast<double>(integrator.lastStats().voxels_updated);
    }
    blocks = static_cast<double>(volume.numBlocks());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(d.frames.size()));
  // Per frame: voxels projected and updated; the map's blocks after the 10 frames.
  state.counters["projected"] = projected / static_cast<double>(d.frames.size());
  state.counters["updated"] = updated / static_cast<double>(d.frames.size());
  state.counters["blocks"] = blocks;
}
BENCHMARK(BM_StageIntegrate)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_StageDepth(benchmark::State& state) {
  Data& d = data();
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < msf::bench::kFrames; ++i)
    frames.push_back(d.sequence.load(i));
  for (auto _ : state)
    for (const Frame& frame : frames)
      benchmark::DoNotOptimize(d.pipeline->computeDepth(frame).fused.depth.data);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
}
BENCHMARK(BM_StageDepth)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_StageOpenSky(benchmark::State& state) {
  Data& d = data();
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < msf::bench::kFrames; ++i)
    frames.push_back(d.sequence.load(i));
  for (auto _ : state) {
    SkyScoring sky(d.sequence.calibration(), d.config.projection, {});
    for (const Frame& frame : frames)
      sky.addFrame(frame);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
}
BENCHMARK(BM_StageOpenSky)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_StageMapPrior(benchmark::State& state) {
  Data& d = data();
  TsdfVolume volume(d.config.volume.voxel_size_m, d.config.volume.truncation_m);
  TsdfIntegrator integrator(volume, d.config.integrator);
  std::vector<cv::Mat> holes;
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    const FrameResult& r = d.results[i];
    integrator.integrateFrame(d.frames[i], r.T_world_cam0,
                              freeSpaceOf(r, r.fused.camera, d.config.fusion, d.sequence.calibration()));
    holes.push_back(mapPriorHoles(r));
  }
  MapPriorConfig prior = d.config.map_prior;
  prior.enabled = true;
  const MapRaycaster raycaster(volume, prior);
  double rays = 0, found = 0;
  cv::Mat depth, weight;
  for (auto _ : state) {
    rays = found = 0;
    for (std::size_t i = 0; i < holes.size(); ++i) {
      raycaster.render(d.results[i].fused.camera, d.results[i].T_world_cam0, holes[i], depth, weight);
      rays += cv::countNonZero(holes[i]);
      found += cv::countNonZero(depth > 0.f);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(holes.size()));
  // Per frame: the rays cast (holes) and those that met the map's surface.
  state.counters["rays"] = rays / static_cast<double>(holes.size());
  state.counters["found"] = found / static_cast<double>(holes.size());
}
BENCHMARK(BM_StageMapPrior)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
