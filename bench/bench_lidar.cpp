// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The LiDAR branch per KITTI frame (odometry 04, frames 0-9 in turn, 1226 x 370): paper
// steps 1 + 2 (projection and compound interpolation) beside the IP-Basic baseline on the
// same projection, in the same run, and the scan's free space all around (ScanFreeSpace, its
// ground plane included). Each benchmark is 20 repetitions of the 10 frames;
// the median and the minimum over repetitions are reported (the minimum is the least
// disturbed by other processes on a shared machine). Wall-clock time, all the threads of OpenCV's pool.
//
//   bench_lidar [--benchmark_filter=Compound]   (MSF_KITTI_DIR overrides the compiled-in path)
#include "kitti_sample.h"

#include <msf/io/pinhole_camera.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/distance_transform.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/reconstruction/scan_free_space.h>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

/// Scans of frames 0-9, loaded once.
struct Data {
  msf::Calibration calibration;
  std::vector<pcl::PointCloud<pcl::PointXYZI>> scans;
  Data() {
    const msf::Sequence sequence = msf::bench::kittiSequence();
    calibration = sequence.calibration();
    scans = msf::bench::kittiScans(sequence);
  }
};

const Data& data() {
  static const Data d;
  return d;
}

/// Scan -> dense depth image of camera 0 (and, when asked, the distance to the returns).
void depth(benchmark::State& state, msf::CompletionMethod method, bool with_distance, int threads) {
  const Data& d = data();
  msf::InterpolationConfig interpolation;
  interpolation.threads = threads;
  msf::LidarCompletion completion(d.calibration, method, msf::ProjectionConfig(), interpolation);
  const int saved = cv::getNumThreads();
  if (threads > 0)
    cv::setNumThreads(threads); // the projection's loops too
  cv::Mat dense, distance;
  std::size_t i = 0, estimates = 0, pixels = 0;
  for (auto _ : state) {
    completion.computeDepth(d.scans[i++ % d.scans.size()], dense, with_distance ? &distance : nullptr);
    benchmark::DoNotOptimize(dense.data);
    estimates += static_cast<std::size_t>(cv::countNonZero(dense));
    pixels += dense.total();
  }
  cv::setNumThreads(saved);
  state.counters["estimated_share"] = pixels ? static_cast<double>(estimates) / pixels : 0.0;
}

void BM_Projection(benchmark::State& state) {
  const Data& d = data();
  const msf::LidarProjector projector(d.calibration);
  cv::Mat canvas;
  std::size_t i = 0;
  for (auto _ : state) {
    projector.projectToCanvas(d.scans[i++ % d.scans.size()], canvas);
    benchmark::DoNotOptimize(canvas.data);
  }
}

void BM_CompoundDepth(benchmark::State& state) { depth(state, msf::CompletionMethod::Compound, false, 0); }
void BM_CompoundDepth1Thread(benchmark::State& state) { depth(state, msf::CompletionMethod::Compound, false, 1); }
void BM_CompoundDepthAndDistance(benchmark::State& state) { depth(state, msf::CompletionMethod::Compound, true, 0); }
void BM_IpBasicFastDepth(benchmark::State& state) { depth(state, msf::CompletionMethod::IpBasicFast, false, 0); }
void BM_IpBasicMultiscaleDepth(benchmark::State& state) {
  depth(state, msf::CompletionMethod::IpBasicMultiscale, false, 0);
}

/// The organized-cloud path of the tools and of the pipeline: the PointXYZID cloud with
/// exact real returns, points on rays, intensity and distance (LidarCompletion::compute).
void BM_CompoundCloud(benchmark::State& state) {
  const Data& d = data();
  msf::LidarCompletion completion(d.calibration);
  pcl::PointCloud<msf::PointXYZID> cloud;
  std::size_t i = 0;
  for (auto _ : state) {
    completion.compute(d.scans[i++ % d.scans.size()], cloud);
    benchmark::DoNotOptimize(cloud.points.data());
  }
}

/// The image-sized cloud path without canvas (LidarProjector::project + CompoundInterpolation).
void BM_ProjectAndFilterCloud(benchmark::State& state) {
  const Data& d = data();
  const msf::LidarProjector projector(d.calibration);
  msf::CompoundInterpolation<msf::PointXYZID> filter;
  filter.setCamera(msf::PinholeCamera::fromCalibration(d.calibration));
  pcl::PointCloud<msf::PointXYZID>::Ptr sparse(new pcl::PointCloud<msf::PointXYZID>);
  pcl::PointCloud<msf::PointXYZID> dense;
  std::size_t i = 0;
  for (auto _ : state) {
    projector.project(d.scans[i++ % d.scans.size()], *sparse);
    filter.setInputCloud(sparse);
    filter.filter(dense);
    benchmark::DoNotOptimize(dense.points.data());
  }
}

/// What a scan says is free all around the sensor (one thread, as the pipeline's depth stage builds it).
void BM_ScanFreeSpace(benchmark::State& state) {
  const Data& d = data();
  std::size_t i = 0;
  for (auto _ : state) {
    const msf::ScanFreeSpace free_space(d.scans[i++ % d.scans.size()]);
    benchmark::DoNotOptimize(free_space.belowGround());
  }
}

double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

} // namespace

#define MSF_LIDAR_BENCH(name)                                                                                  \
  BENCHMARK(name)                                                                                              \
      ->Unit(benchmark::kMillisecond)                                                                          \
      ->UseRealTime()                                                                                          \
      ->Iterations(10)                                                                                         \
      ->Repetitions(20)                                                                                        \
      ->ReportAggregatesOnly(true)                                                                             \
      ->ComputeStatistics("min", minimum)

MSF_LIDAR_BENCH(BM_Projection);
MSF_LIDAR_BENCH(BM_CompoundDepth);
MSF_LIDAR_BENCH(BM_CompoundDepth1Thread);
MSF_LIDAR_BENCH(BM_CompoundDepthAndDistance);
MSF_LIDAR_BENCH(BM_CompoundCloud);
MSF_LIDAR_BENCH(BM_ProjectAndFilterCloud);
MSF_LIDAR_BENCH(BM_IpBasicFastDepth);
MSF_LIDAR_BENCH(BM_IpBasicMultiscaleDepth);
MSF_LIDAR_BENCH(BM_ScanFreeSpace);

BENCHMARK_MAIN();
