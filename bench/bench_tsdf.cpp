// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// TSDF integration and meshing on KITTI odometry 04 frames 0-9 (SGBM depth, 0.1 m voxels,
// 0.3 m truncation), side by side with Open3D 0.16's ScalableTSDFVolume on the very same
// depth images and poses (bench/open3d_tsdf.py, run by this program when Debian's
// python3-open3d is installed): once with every core for both, once with one thread each.
//
//   bench_tsdf [--benchmark_repetitions=5]   (MSF_KITTI_DIR overrides the compiled-in path,
//                                             MSF_OPEN3D_PYTHON the interpreter, default /usr/bin/python3)
#include "kitti_sample.h"

#include <msf/common/statistics.h>
#include <msf/io/calibration.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/sequence.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstring>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

namespace fs = std::filesystem;
using namespace msf;

namespace {

constexpr double kVoxel = 0.1, kTrunc = 0.3, kMaxDepth = 40.0;
constexpr int kFrames = static_cast<int>(msf::bench::kFrames);

/// SGBM depth of the KITTI frames (as the baseline docs/results.md quotes: 3-way, 128 disparities, block 5),
/// also written as KITTI depth PNGs for the Open3D script.
struct Data {
  std::vector<DepthFrame> frames;
  PoseList poses;
  std::string dir; // depth/, color/, poses.txt, camera.txt
  Data() {
    const Sequence sequence = msf::bench::kittiSequence();
    const PinholeCamera camera = PinholeCamera::fromCalibration(sequence.calibration());
    cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(0, 128, 5, 8 * 25, 32 * 25, 1, 63, 10, 100, 2,
                                                          cv::StereoSGBM::MODE_SGBM_3WAY);
    dir = (fs::temp_directory_path() / ("msf_bench_tsdf_" + std::to_string(::getpid()))).string();
    fs::create_directories(dir + "/depth");
    fs::create_directories(dir + "/color");
    for (int i = 0; i < kFrames; ++i) {
      const Frame f = sequence.load(static_cast<std::size_t>(i), false);
      cv::Mat disparity16;
      sgbm->compute(f.left, f.right, disparity16);
      DepthFrame frame;
      frame.camera = camera;
      cv::Mat disparity_px; // OpenCV's fixed point, 1/16 px
      disparity16.convertTo(disparity_px, CV_32F, 1.0 / 16.0);
      frame.depth = msf::disparityToDepth(disparity_px, sequence.calibration());
      cv::cvtColor(f.left, frame.color, cv::COLOR_GRAY2BGR);
      char name[32];
      std::snprintf(name, sizeof name, "%06d.png", i);
      // The PNG rounds depth to 1/256 m; both sides integrate the rounded depth.
      writeKittiDepthPng(dir + "/depth/" + name, frame.depth);
      frame.depth = readKittiDepthPng(dir + "/depth/" + name);
      writeImage(dir + "/color/" + name, frame.color);
      frames.push_back(frame);
      poses.push_back(f.T_world_cam0);
    }
    saveOdometryPoses(dir + "/poses.txt", poses);
    std::ofstream(dir + "/camera.txt") << camera.width << ' ' << camera.height << ' ' << camera.fx << ' ' << camera.fy
                                       << ' ' << camera.cx << ' ' << camera.cy << '\n';
  }
  ~Data() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

Data& data() {
  static Data d;
  return d;
}

TsdfIntegrator::Config integratorConfig(double lambda) {
  TsdfIntegrator::Config c;
  c.lambda = lambda;
  c.max_depth_m = kMaxDepth;
  return c;
}

/// One iteration: the 10 frames into a fresh volume; the time reported is per frame.
void BM_TsdfIntegrate(benchmark::State& state) {
  Data& d = data();
  const double lambda = static_cast<double>(state.range(0));
  std::size_t blocks = 0;
  double allocate = 0, update = 0, regularize = 0, voxels = 0;
  for (auto _ : state) {
    TsdfVolume volume(kVoxel, kTrunc);
    TsdfIntegrator integrator(volume, integratorConfig(lambda));
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kFrames; ++i) {
      integrator.integrate(d.frames[i], d.poses[i]);
      const auto& s = integrator.lastStats();
      allocate += s.allocate_ms;
      update += s.update_ms;
      regularize += s.regularize_ms;
      voxels += static_cast<double>(s.voxels_updated);
    }
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / kFrames);
    blocks = volume.numBlocks();
  }
  // Stage times per frame (ms) and voxels updated per frame.
  const double n = static_cast<double>(state.iterations()) * kFrames;
  state.counters["alloc_ms"] = allocate / n;
  state.counters["update_ms"] = update / n;
  state.counters["reg_ms"] = regularize / n;
  state.counters["voxels"] = voxels / n;
  state.counters["blocks"] = static_cast<double>(blocks);
}
BENCHMARK(BM_TsdfIntegrate)->Arg(0)->Arg(5)->ArgName("lambda")->UseManualTime()->Unit(benchmark::kMillisecond);

const TsdfVolume& tenFrameMap() {
  static std::unique_ptr<TsdfVolume> volume = [] {
    auto v = std::make_unique<TsdfVolume>(kVoxel, kTrunc);
    TsdfIntegrator integrator(*v, integratorConfig(0.0));
    for (int i = 0; i < kFrames; ++i)
      integrator.integrate(data().frames[i], data().poses[i]);
    return v;
  }();
  return *volume;
}

/// Full extraction of the 10-frame map into a pcl::PolygonMesh (a new mesher each time).
void BM_MarchingCubesFull(benchmark::State& state) {
  const TsdfVolume& volume = tenFrameMap();
  pcl::PolygonMesh mesh;
  for (auto _ : state) {
    MarchingCubes mesher;
    mesher.extract(volume, mesh);
    benchmark::DoNotOptimize(mesh.polygons.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.polygons.size());
  state.counters["vertices"] = static_cast<double>(mesh.cloud.width);
}
BENCHMARK(BM_MarchingCubesFull)->Unit(benchmark::kMillisecond);

/// Incremental extraction after integrating one more frame into the 10-frame map.
void BM_MarchingCubesIncremental(benchmark::State& state) {
  Data& d = data();
  TsdfVolume volume(kVoxel, kTrunc);
  TsdfIntegrator integrator(volume, integratorConfig(0.0));
  MarchingCubes mesher;
  TriangleMesh mesh;
  for (int i = 0; i < kFrames; ++i)
    integrator.integrate(d.frames[i], d.poses[i]);
  mesher.extract(volume, mesh);
  int next = 0;
  std::size_t meshed = 0;
  for (auto _ : state) {
    state.PauseTiming();
    integrator.integrate(d.frames[next], d.poses[next]);
    next = (next + 1) % kFrames;
    state.ResumeTiming();
    mesher.extract(volume, mesh);
    meshed = mesher.lastStats().blocks_meshed;
  }
  state.counters["blocks_meshed"] = static_cast<double>(meshed);
  state.counters["blocks"] = static_cast<double>(volume.numBlocks());
}
BENCHMARK(BM_MarchingCubesIncremental)->Unit(benchmark::kMillisecond);

/// Full extraction into a TriangleMesh (what Open3D's extract_triangle_mesh returns).
void BM_MarchingCubesFullTriangleMesh(benchmark::State& state) {
  const TsdfVolume& volume = tenFrameMap();
  TriangleMesh mesh;
  for (auto _ : state) {
    MarchingCubes mesher;
    mesher.extract(volume, mesh);
    benchmark::DoNotOptimize(mesh.triangles.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}
BENCHMARK(BM_MarchingCubesFullTriangleMesh)->Unit(benchmark::kMillisecond);

/// The 10-frame map written as volume.pcd (binary compressed, what msf_reconstruct saves), into
/// /dev/shm: the CPU's cost, not a disk's.
void BM_VolumeSave(benchmark::State& state) {
  const TsdfVolume& volume = tenFrameMap();
  const std::string path = "/dev/shm/msf_bench_volume_" + std::to_string(::getpid()) + ".pcd";
  for (auto _ : state)
    volume.save(path);
  state.counters["voxels"] = static_cast<double>(volume.numObservedVoxels());
  state.counters["MB"] = static_cast<double>(fs::file_size(path)) / 1e6;
  fs::remove(path);
}
BENCHMARK(BM_VolumeSave)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The same file read back (msf_mesh, msf_integrate -volume).
void BM_VolumeLoad(benchmark::State& state) {
  const std::string path = "/dev/shm/msf_bench_volume_load_" + std::to_string(::getpid()) + ".pcd";
  tenFrameMap().save(path);
  for (auto _ : state)
    benchmark::DoNotOptimize(TsdfVolume::load(path).numBlocks());
  fs::remove(path);
}
BENCHMARK(BM_VolumeLoad)->Unit(benchmark::kMillisecond)->UseRealTime();

double cpuMs() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}
double wallMs() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Wall and process CPU time (all threads) of one measured thing, medians over repetitions.
struct Timing {
  std::vector<double> wall, cpu;
  void add(double w, double c) {
    wall.push_back(w);
    cpu.push_back(c);
  }
  double medianWall() const { return median(wall); }
  double medianCpu() const { return median(cpu); }
};

/// The side-by-side protocol, the same as bench/open3d_tsdf.py: a fresh volume, the 10 frames
/// integrated (time per frame), then one extraction of the 10-frame map.
struct Ours {
  Timing integrate0, integrate5, mesh, polygon_mesh;
  std::size_t vertices = 0, triangles = 0;
};

Ours measureOurs(int repetitions) {
  Data& d = data();
  Ours ours;
  for (int r = 0; r < repetitions; ++r)
    for (const double lambda : {0.0, 5.0}) {
      TsdfVolume volume(kVoxel, kTrunc);
      TsdfIntegrator integrator(volume, integratorConfig(lambda));
      double w = wallMs(), c = cpuMs();
      for (int i = 0; i < kFrames; ++i)
        integrator.integrate(d.frames[i], d.poses[i]);
      (lambda == 0 ? ours.integrate0 : ours.integrate5).add((wallMs() - w) / kFrames, (cpuMs() - c) / kFrames);
      if (lambda != 0)
        continue;
      TriangleMesh mesh;
      w = wallMs(), c = cpuMs();
      MarchingCubes().extract(volume, mesh);
      ours.mesh.add(wallMs() - w, cpuMs() - c);
      pcl::PolygonMesh polygon_mesh;
      w = wallMs(), c = cpuMs();
      MarchingCubes().extract(volume, polygon_mesh);
      ours.polygon_mesh.add(wallMs() - w, cpuMs() - c);
      ours.vertices = mesh.vertices.size();
      ours.triangles = mesh.triangles.size();
    }
  return ours;
}

/// `threads` 0 = Open3D's default (every core).
std::map<std::string, double> runOpen3d(int repetitions, int threads) {
  const char* env = std::getenv("MSF_OPEN3D_PYTHON");
  const std::string python = env ? env : "/usr/bin/python3";
  const std::string script = (fs::path(__FILE__).parent_path() / "open3d_tsdf.py").string();
  const std::string out = data().dir + "/open3d.json";
  std::ostringstream cmd;
  if (threads > 0)
    cmd << "OMP_NUM_THREADS=" << threads << " ";
  cmd << python << " " << script << " " << data().dir << " --voxel " << kVoxel << " --trunc " << kTrunc
      << " --max-depth " << kMaxDepth << " --repetitions " << repetitions << " > " << out;
  std::map<std::string, double> result;
  if (std::system(cmd.str().c_str()) != 0)
    return result;
  std::ifstream in(out);
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* key : {"integrate_ms_per_frame", "extract_ms", "integrate_cpu_ms_per_frame", "extract_cpu_ms",
                          "vertices", "triangles"}) {
    const auto at = json.find(std::string("\"") + key + "\": ");
    if (at != std::string::npos)
      result[key] = std::atof(json.c_str() + at + std::strlen(key) + 4);
  }
  return result;
}

} // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  data(); // SGBM once, before any timing (exits with an error without the KITTI sample)
  benchmark::RunSpecifiedBenchmarks();

  // Both with every core (2 here), then both on one thread: the CPU time per frame is what
  // integration takes from the other stages when they share the cores (the pipeline).
  constexpr int kRepetitions = 5;
  const int cores = cv::getNumThreads();
  for (const int threads : {cores, 1}) {
    cv::setNumThreads(threads);
    const Ours ours = measureOurs(kRepetitions);
    const auto o3d = runOpen3d(kRepetitions, threads == cores ? 0 : threads);
    std::printf("\nSide by side, %d thread%s: KITTI odometry 04 frames 0-%d, SGBM depth (3-way, 128 disparities, block 5), "
                "%.1f m voxels, %.1f m truncation, depth <= %.0f m;\nmedians of %d runs, wall time and process CPU "
                "time over all threads (the cores may be shared: CPU time is the steadier figure).\n\n",
                threads, threads == 1 ? "" : "s", kFrames - 1, kVoxel, kTrunc, kMaxDepth, kRepetitions);
    std::printf("  %-38s %10s %10s %12s %12s\n", "", "wall ms", "CPU ms", "Open3D wall", "Open3D CPU");
    const bool have = o3d.count("integrate_ms_per_frame") && o3d.count("extract_ms") &&
                      o3d.count("integrate_cpu_ms_per_frame") && o3d.count("extract_cpu_ms");
    auto row = [&](const char* name, const Timing& t, const char* key_wall, const char* key_cpu) {
      std::printf("  %-38s %10.1f %10.1f", name, t.medianWall(), t.medianCpu());
      if (have && key_wall)
        std::printf(" %12.1f %12.1f   -> %.1fx (wall), %.1fx (CPU) faster", o3d.at(key_wall), o3d.at(key_cpu),
                    o3d.at(key_wall) / t.medianWall(), o3d.at(key_cpu) / t.medianCpu());
      std::printf("\n");
    };
    row("integrate per frame, lambda 0", ours.integrate0, "integrate_ms_per_frame", "integrate_cpu_ms_per_frame");
    row("integrate per frame, lambda 5", ours.integrate5, nullptr, nullptr);
    row("mesh, 10-frame map (TriangleMesh)", ours.mesh, "extract_ms", "extract_cpu_ms");
    row("mesh, 10-frame map (pcl::PolygonMesh)", ours.polygon_mesh, "extract_ms", "extract_cpu_ms");
    std::printf("  lambda 5 / lambda 0 integration: %.2fx (wall), %.2fx (CPU)\n",
                ours.integrate5.medianWall() / ours.integrate0.medianWall(),
                ours.integrate5.medianCpu() / ours.integrate0.medianCpu());
    std::printf("  mesh size: msfusion %zu vertices, %zu triangles", ours.vertices, ours.triangles);
    if (have)
      std::printf("; Open3D %.0f vertices, %.0f triangles", o3d.count("vertices") ? o3d.at("vertices") : 0.0,
                  o3d.count("triangles") ? o3d.at("triangles") : 0.0);
    std::printf("\n");
    if (!have)
      std::printf("  Open3D: not run (needs Debian's python3-open3d and python3-numpy: make deps-bench)\n");
  }
  cv::setNumThreads(cores);
  benchmark::Shutdown();
  return 0;
}
