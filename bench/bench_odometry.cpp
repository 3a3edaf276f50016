// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// LiDAR odometry per KITTI frame (odometry 04, frames 0-9 in turn, ~120k returns a scan): each
// frame registered to the local map of the frames before it, from a fresh odometry every
// 10 frames (the first frame only starts the map). One thread: the registration has no
// parallel loop. 20 repetitions of the 10 frames; the median and the minimum over
// repetitions are reported (the minimum is the least disturbed by other processes).
//
//   bench_odometry [--benchmark_filter=Deskew]   (MSF_KITTI_DIR overrides the compiled-in path)
#include "kitti_sample.h"

#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/registration/sweep_deskew.h>
#include <msf/registration/voxel_downsample.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace {

/// Scans of frames 0-9, loaded once.
struct Data {
  std::vector<pcl::PointCloud<pcl::PointXYZI>> scans = msf::bench::kittiScans(msf::bench::kittiSequence());
};

const Data& data() {
  static const Data d;
  return d;
}

void odometry(benchmark::State& state, const msf::LidarOdometry::Config& config) {
  const Data& d = data();
  std::unique_ptr<msf::LidarOdometry> odometry;
  std::size_t i = 0, iterations = 0, source_points = 0, searches = 0;
  for (auto _ : state) {
    if (i % d.scans.size() == 0) {
      state.PauseTiming();
      odometry = std::make_unique<msf::LidarOdometry>(config);
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(odometry->registerScan(d.scans[i++ % d.scans.size()]));
    iterations += static_cast<std::size_t>(odometry->lastStats().iterations);
    source_points += odometry->lastStats().source_points;
    searches += odometry->lastStats().searches;
  }
  state.counters["icp_iterations"] = static_cast<double>(iterations) / static_cast<double>(i);
  state.counters["source_points"] = static_cast<double>(source_points) / static_cast<double>(i);
  state.counters["searches"] = static_cast<double>(searches) / static_cast<double>(i);
}

/// The defaults: point-to-plane where the map is planar, scans deskewed as sweeps.
void BM_Odometry(benchmark::State& state) { odometry(state, msf::LidarOdometry::Config{}); }

/// Point-to-point everywhere (KISS-ICP's residual), for comparison.
void BM_OdometryPointToPoint(benchmark::State& state) {
  msf::LidarOdometry::Config config;
  config.point_to_plane = false;
  odometry(state, config);
}

/// The first scan as the odometry's points, and a sweep's motion at KITTI's speed.
struct SweepCase {
  msf::PointList points;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  SweepCase() {
    for (const auto& p : data().scans.front())
      points.emplace_back(p.x, p.y, p.z);
    motion.translation() << 1.3, 0.0, 0.0;
  }
};

/// The motion compensation alone, of a whole scan.
void BM_Deskew(benchmark::State& state) {
  const SweepCase c;
  for (auto _ : state)
    benchmark::DoNotOptimize(msf::deskewSweep(c.points, c.motion));
}

/// A scan's returns in range, deskewed and downsampled to the map's half voxel with their
/// moments (LidarOdometry's first step; VoxelDownsampler::downsampleScan).
void BM_DownsampleScan(benchmark::State& state) {
  const SweepCase c;
  const msf::SweepDeskew deskew(c.motion);
  msf::VoxelDownsampler downsampler;
  msf::PointList kept;
  std::vector<msf::PointMoments> moments;
  for (auto _ : state)
    benchmark::DoNotOptimize(downsampler.downsampleScan(c.points, 3.0, 100.0, &deskew, 0.5, kept, &moments));
  state.counters["kept"] = static_cast<double>(kept.size());
}

double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

} // namespace

#define MSF_ODOMETRY_BENCH(name)                                                                               \
  BENCHMARK(name)                                                                                              \
      ->Unit(benchmark::kMillisecond)                                                                          \
      ->Iterations(10)                                                                                         \
      ->Repetitions(20)                                                                                        \
      ->ReportAggregatesOnly(true)                                                                             \
      ->ComputeStatistics("min", minimum)

MSF_ODOMETRY_BENCH(BM_Odometry);
MSF_ODOMETRY_BENCH(BM_OdometryPointToPoint);
MSF_ODOMETRY_BENCH(BM_Deskew);
MSF_ODOMETRY_BENCH(BM_DownsampleScan);

BENCHMARK_MAIN();
