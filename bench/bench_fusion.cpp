// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Per-pixel depth fusion per KITTI frame (odometry 04, frames 0-9 in turn, 1226 x 370):
// the cloud class DepthFusion<PointXYZID, PointXYZRGBConfidence, PointXYZRGBWeight> and the
// image-level DepthImageFusion, for both methods, and the facade extension after it
// (extendFacades on the fused depth, its copy not timed), and the rig's check beside them. Inputs (interpolated LiDAR with distances,
// SGBM with confidence) are made once before timing; cpu_ms_all_threads is the process CPU
// time per frame (all threads).
//
//   bench_fusion [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
//   (MSF_KITTI_DIR overrides the compiled-in path of the KITTI sample)
#include "kitti_sample.h"

#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/facade_extension.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/rig_agreement.h>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/distance_transform.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/real_returns.h>
#include <msf/reconstruction/silhouette_thickness.h>
#include <msf/stereo/sgbm_stereo.h>

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <ctime>
#include <vector>

namespace {

struct Data {
  msf::Calibration calibration;
  std::vector<pcl::PointCloud<msf::PointXYZID>::Ptr> lidar;
  std::vector<pcl::PointCloud<msf::PointXYZRGBConfidence>::Ptr> stereo;
  std::vector<cv::Mat> lidar_depth, lidar_distance, stereo_depth, stereo_confidence, left, color;
  Data() {
    const msf::Sequence sequence = msf::bench::kittiSequence();
    calibration = sequence.calibration();
    msf::LidarProjector projector(calibration);
    msf::CompoundInterpolation<msf::PointXYZID> interpolation;
    interpolation.setCamera(msf::PinholeCamera::fromCalibration(calibration));
    msf::SgbmStereo sgbm;
    sgbm.setCalibration(calibration);
    for (std::size_t i = 0; i < msf::bench::kFrames && i < sequence.size(); ++i) {
      const msf::Frame f = sequence.load(i, true);
      pcl::PointCloud<msf::PointXYZID>::Ptr sparse(new pcl::PointCloud<msf::PointXYZID>);
      pcl::PointCloud<msf::PointXYZID>::Ptr dense(new pcl::PointCloud<msf::PointXYZID>);
      projector.project(*f.scan, *sparse);
      interpolation.setInputCloud(sparse);
      interpolation.filter(*dense);
      pcl::PointCloud<msf::PointXYZRGBConfidence>::Ptr matched(new pcl::PointCloud<msf::PointXYZRGBConfidence>);
      sgbm.setInputImages(f.left, f.right);
      sgbm.setInputColor(f.color);
      sgbm.setDepthPrior(msf::cloudToDepthImage(*dense));
      sgbm.compute(*matched);
      lidar.push_back(dense);
      stereo.push_back(matched);
      lidar_depth.push_back(msf::cloudToDepthImage(*dense));
      cv::Mat distance(lidar_depth.back().size(), CV_32FC1);
      for (int v = 0; v < distance.rows; ++v)
        for (int u = 0; u < distance.cols; ++u)
          distance.at<float>(v, u) = dense->at(u, v).distance;
      lidar_distance.push_back(distance);
      stereo_depth.push_back(sgbm.getDepth());
      stereo_confidence.push_back(sgbm.getConfidence().clone());
      left.push_back(f.left);
      color.push_back(f.color);
    }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

void cloudFusion(benchmark::State& state, msf::FusionMethod method) {
  const Data& d = data();
  msf::DepthFusionConfig config;
  config.method = method;
  msf::DepthFusion<> fusion(config);
  fusion.setCalibration(d.calibration);
  pcl::PointCloud<msf::PointXYZRGBWeight> out;
  std::size_t i = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    fusion.setInputLidar(d.lidar[f]);
    fusion.setInputStereo(d.stereo[f]);
    fusion.fuse(out);
    benchmark::DoNotOptimize(out.points.data());
  }
  state.counters["cpu_ms_all_threads"] =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
}

void imageFusion(benchmark::State& state, msf::FusionMethod method, bool edge_support = true) {
  const Data& d = data();
  msf::DepthFusionConfig config;
  config.method = method;
  config.edge_support = edge_support;
  msf::DepthImageFusion fusion(config);
  fusion.setCalibration(d.calibration);
  cv::Mat fused, weight;
  std::size_t i = 0;
  const std::clock_t cpu_start = std::clock();
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    fusion.fuse(d.lidar_depth[f], d.lidar_distance[f], d.stereo_depth[f], d.stereo_confidence[f], fused, &weight);
    benchmark::DoNotOptimize(fused.data);
  }
  state.counters["cpu_ms_all_threads"] =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / static_cast<double>(state.iterations());
}

/// The fused frames (depth, weight, free-space weight) of the sample, with the default fusion.
struct FusedFrames {
  std::vector<cv::Mat> depth, weight, free;
  explicit FusedFrames(const Data& d) : depth(d.lidar.size()), weight(d.lidar.size()), free(d.lidar.size()) {
    msf::DepthImageFusion fusion{msf::DepthFusionConfig()};
    fusion.setCalibration(d.calibration);
    for (std::size_t f = 0; f < d.lidar.size(); ++f)
      fusion.fuse(d.lidar_depth[f], d.lidar_distance[f], d.stereo_depth[f], d.stereo_confidence[f], depth[f],
                  &weight[f], &free[f]);
  }
};

void BM_FacadeExtension(benchmark::State& state) {
  const Data& d = data();
  const msf::DepthFusionConfig config;
  const FusedFrames fused(d);
  const auto& [depth, weight, free] = fused;
  const msf::PinholeCamera camera = msf::PinholeCamera::fromCalibration(d.calibration);
  cv::Mat z, w, fw;
  std::size_t i = 0, extended = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    state.PauseTiming();
    depth[f].copyTo(z);
    weight[f].copyTo(w);
    free[f].copyTo(fw);
    state.ResumeTiming();
    extended += msf::extendFacades(d.left[f], camera, config, z, w, fw);
  }
  state.counters["pixels_extended"] = static_cast<double>(extended) / static_cast<double>(state.iterations());
}

/// The integrator's silhouette_band step on the fused frames: the thickness each pixel's object
/// is seen to have (msf::silhouetteThickness), which bounds the band behind it.
void BM_SilhouetteThickness(benchmark::State& state) {
  const Data& d = data();
  const FusedFrames fused(d);
  const msf::PinholeCamera camera = msf::PinholeCamera::fromCalibration(d.calibration);
  cv::Mat thickness;
  std::size_t i = 0;
  double bounded = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    msf::silhouetteThickness(fused.depth[f], fused.weight[f], camera, 0.1f, 1.f, thickness);
    state.PauseTiming();
    bounded += cv::countNonZero(thickness < 1e30f);
    state.ResumeTiming();
  }
  state.counters["pixels_bounded"] = bounded / static_cast<double>(state.iterations());
}

/// The open sky of a frame (SkyMask::compute on the colour image and the real returns) and its
/// clear sky (SkyMask::clearSky), as the fusion finds them with fusion.clear_sky.
void BM_SkyMask(benchmark::State& state) {
  const Data& d = data();
  const msf::SkyMask sky;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    const cv::Mat open = sky.compute(d.color[f], msf::realReturns(d.lidar_depth[f], d.lidar_distance[f]));
    benchmark::DoNotOptimize(sky.clearSky(d.color[f], open).data);
  }
}

/// The rig's check the engine runs after the fusion: the share of pixels where the LiDAR's real
/// return and the stereo depth differ (msf::lidarStereoDisagreement), beside the fusion's cost.
void BM_LidarStereoDisagreement(benchmark::State& state) {
  const Data& d = data();
  std::size_t i = 0;
  double share = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % d.lidar.size();
    share += msf::lidarStereoDisagreement(d.lidar_depth[f], d.lidar_distance[f], d.stereo_depth[f]);
  }
  state.counters["share"] = share / static_cast<double>(state.iterations());
}

void BM_FusionCloudPaper(benchmark::State& s) { cloudFusion(s, msf::FusionMethod::Paper); }
void BM_FusionCloudUncertainty(benchmark::State& s) { cloudFusion(s, msf::FusionMethod::Uncertainty); }
void BM_FusionImagePaper(benchmark::State& s) { imageFusion(s, msf::FusionMethod::Paper); }
void BM_FusionImageUncertainty(benchmark::State& s) { imageFusion(s, msf::FusionMethod::Uncertainty); }
// The same without its last step (fusion.edge_support), for that step's cost side by side.
void BM_FusionImageUncertaintyNoEdgeSupport(benchmark::State& s) {
  imageFusion(s, msf::FusionMethod::Uncertainty, false);
}

} // namespace

BENCHMARK(BM_FusionCloudPaper)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_FusionCloudUncertainty)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_FusionImagePaper)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_FusionImageUncertainty)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_FusionImageUncertaintyNoEdgeSupport)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_FacadeExtension)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->Iterations(50);
BENCHMARK(BM_SkyMask)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_LidarStereoDisagreement)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(50);
BENCHMARK(BM_SilhouetteThickness)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->Iterations(50);

BENCHMARK_MAIN();
