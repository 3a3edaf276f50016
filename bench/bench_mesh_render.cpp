// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Depth rendering of a mesh into a KITTI-sized image (1241x376), what evaluation protocol 4
// does at every frame's pose (MeshRasterizer, buffers kept between calls as msf_reconstruct
// keeps them):
//  - BM_RenderStreetMillionTriangles: a 1M-triangle street canyon (ground and two facades
//    with relief) wholly in view, the worst case: every triangle is projected and drawn;
//  - BM_RenderKittiMap: the map of odometry 04 frames 0-9 made by the pipeline (default
//    configuration), rendered at each frame's pose in turn;
//  - BM_RenderLongDrive/layout:0|1/bounds:0|1: that map copied 21 or 25 times, along a straight
//    road or on a town's grid of streets, rendered whole and with its runs' bounds
//    (MeshRasterizer::triangleRunBounds), which skip what is outside the view.
//
// cpu_ms_all_threads is the process CPU time per render (all threads): on a machine shared with
// other work it stays close to the quiet figure when the wall time does not.
//
//   bench_mesh_render [--benchmark_repetitions=5]   (MSF_KITTI_DIR overrides the compiled-in path)
#include "kitti_sample.h"

#include <msf/io/pinhole_camera.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <ctime>

using namespace msf;

namespace {

PinholeCamera kittiCamera() {
  PinholeCamera c;
  c.width = 1241, c.height = 376;
  c.fx = c.fy = 707.0912f;
  c.cx = 601.8873f, c.cy = 183.1104f;
  return c;
}

double cpuMsPerIteration(std::clock_t start, const benchmark::State& state) {
  return 1000.0 * static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
}

/// A street 16 m wide between facades 8 m high, from 2 m to 80 m ahead of the camera: one
/// grid over (across, along) folded into a U, `across` x `along` quads, 2 triangles each.
TriangleMesh streetCanyon(int across, int along) {
  TriangleMesh mesh;
  for (int j = 0; j <= along; ++j) {
    const float z = 2.f + 78.f * static_cast<float>(j) / static_cast<float>(along);
    for (int i = 0; i <= across; ++i) {
      const float s = 32.f * static_cast<float>(i) / static_cast<float>(across); // metres along the U
      const float relief = 0.05f * std::sin(3.f * s) * std::cos(0.7f * z);
      Eigen::Vector3f p;
      if (s < 8.f)
        p = {-8.f + relief, 1.65f - (8.f - s), z};      // left facade, top down
      else if (s < 24.f)
        p = {s - 16.f, 1.65f + relief, z};             // the ground
      else
        p = {8.f + relief, 1.65f - (s - 24.f), z};     // right facade, bottom up
      mesh.vertices.push_back(p);
      mesh.colors.push_back({128, 128, 128});
    }
  }
  const auto row = static_cast<std::uint32_t>(across + 1);
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < across; ++i) {
      const std::uint32_t a = static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
      mesh.triangles.push_back({a, a + 1, a + row + 1});
      mesh.triangles.push_back({a, a + row + 1, a + row});
    }
  return mesh;
}

void BM_RenderStreetMillionTriangles(benchmark::State& state) {
  const TriangleMesh mesh = streetCanyon(1000, 500);
  MeshRasterizer rasterizer;
  cv::Mat depth;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    rasterizer.render(mesh, kittiCamera(), Eigen::Isometry3d::Identity(), depth);
    benchmark::DoNotOptimize(depth.data);
  }
  state.counters["cpu_ms_all_threads"] = cpuMsPerIteration(cpu_start, state);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["covered_px"] = cv::countNonZero(depth);
}
BENCHMARK(BM_RenderStreetMillionTriangles)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The pipeline's map of the KITTI frames and their poses, made once.
struct KittiMap {
  TriangleMesh mesh;
  PinholeCamera camera;
  std::vector<Eigen::Isometry3d> poses;
  KittiMap() {
    const Sequence sequence = msf::bench::kittiSequence();
    Reconstructor pipeline(sequence.calibration(), PipelineConfig());
    for (std::size_t i = 0; i < msf::bench::kFrames; ++i) {
      const Frame frame = sequence.load(i);
      FrameResult result = pipeline.computeDepth(frame);
      pipeline.integrate(result);
      poses.push_back(frame.T_world_cam0);
    }
    mesh = pipeline.mesh();
    camera = PinholeCamera::fromCalibration(sequence.calibration());
  }
};

void BM_RenderKittiMap(benchmark::State& state) {
  static const KittiMap map;
  MeshRasterizer rasterizer;
  cv::Mat depth;
  std::size_t frame = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    rasterizer.render(map.mesh, map.camera, map.poses[frame], depth);
    benchmark::DoNotOptimize(depth.data);
    frame = (frame + 1) % map.poses.size();
  }
  state.counters["cpu_ms_all_threads"] = cpuMsPerIteration(cpu_start, state);
  state.counters["triangles"] = static_cast<double>(map.mesh.triangles.size());
  state.counters["covered_px"] = cv::countNonZero(depth);
}
BENCHMARK(BM_RenderKittiMap)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The KITTI map copied 21 times: along the drive, 60 m apart (layout 0: a straight road, half
/// of it behind the camera), or on a 5 x 5 grid 100 m apart, the middle copy at the centre
/// (layout 1: a town's streets); the camera at the middle copy's poses.
const TriangleMesh& copiedMap(const KittiMap& map, int layout) {
  static std::map<int, TriangleMesh> made;
  TriangleMesh& mesh = made[layout];
  if (!mesh.triangles.empty())
    return mesh;
  const Eigen::Vector3d along = (map.poses.back().translation() - map.poses.front().translation()).normalized();
  const Eigen::Vector3d across = along.cross(Eigen::Vector3d::UnitY()).normalized(); // camera y is down
  std::vector<Eigen::Vector3d> offsets;
  for (int k = -10; k <= 10 && layout == 0; ++k)
    offsets.push_back(60.0 * k * along);
  for (int i = -2; i <= 2 && layout == 1; ++i)
    for (int j = -2; j <= 2; ++j)
      offsets.push_back(100.0 * i * along + 100.0 * j * across);
  for (const Eigen::Vector3d& offset : offsets) {
    const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
    for (const Eigen::Vector3f& v : map.mesh.vertices)
      mesh.vertices.push_back(v + offset.cast<float>());
    for (const auto& t : map.mesh.triangles)
      mesh.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
  }
  return mesh;
}

void BM_RenderLongDrive(benchmark::State& state) {
  static const KittiMap map;
  const TriangleMesh& drive = copiedMap(map, static_cast<int>(state.range(0)));
  const bool with_bounds = state.range(1) != 0;
  const MeshRasterizer::RunBounds bounds = MeshRasterizer::triangleRunBounds(drive);
  MeshRasterizer rasterizer;
  cv::Mat depth;
  std::size_t frame = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    rasterizer.render(drive, map.camera, map.poses[frame], depth, nullptr, with_bounds ? &bounds : nullptr);
    benchmark::DoNotOptimize(depth.data);
    frame = (frame + 1) % map.poses.size();
  }
  state.counters["cpu_ms_all_threads"] = cpuMsPerIteration(cpu_start, state);
  state.counters["triangles"] = static_cast<double>(drive.triangles.size());
}
BENCHMARK(BM_RenderLongDrive)
    ->ArgNames({"layout", "bounds"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace

BENCHMARK_MAIN();
