// TSDF integration and meshing on KITTI odometry 04 frames 0-9 (SGBM depth, 0.1 m voxels,
// 0.3 m truncation), side by side with Open3D 0.16's ScalableTSDFVolume on the very same
// depth images and poses (bench/open3d_tsdf.py, run by this program when Debian's
// python3-open3d is installed).
//
//   bench_tsdf [--benchmark_repetitions=5]   (MSF_KITTI_DIR overrides the compiled-in path,
//                                             MSF_OPEN3D_PYTHON the interpreter, default /usr/bin/python3)
#include <msf/common/statistics.h>
#include <msf/io/calibration.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
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
constexpr int kFrames = 10;

std::string kittiDir() {
  const char* env = std::getenv("MSF_KITTI_DIR");
  return env ? env : MSF_KITTI_DIR;
}

/// SGBM depth of the KITTI frames (as DESIGN.md's baseline: 3-way, 128 disparities, block 5),
/// also written as KITTI depth PNGs for the Open3D script.
struct Data {
  std::vector<DepthFrame> frames;
  PoseList poses;
  std::string dir; // depth/, color/, poses.txt, camera.txt
  Data() {
    const Sequence sequence(kittiDir() + "/odometry/sequences/04");
    const PinholeCamera camera = PinholeCamera::fromCalibration(sequence.calibration());
    const double fB = sequence.calibration().focalBaseline();
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
      frame.depth.create(f.left.size(), CV_32FC1);
      for (int v = 0; v < f.left.rows; ++v)
        for (int u = 0; u < f.left.cols; ++u) {
          const float d = disparity16.at<std::int16_t>(v, u) / 16.f;
          frame.depth.at<float>(v, u) = d > 0.f ? static_cast<float>(fB / d) : 0.f;
        }
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

/// Keeps the median of each benchmark's repetitions for the side-by-side table.
class MedianReporter : public benchmark::ConsoleReporter {
public:
  std::map<std::string, double> median_ms;
  std::map<std::string, double> last_ms;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      const double ms = r.GetAdjustedRealTime() * (r.time_unit == benchmark::kMillisecond ? 1.0 : 1e-6);
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median")
        median_ms[r.run_name.str()] = ms;
      else if (r.run_type == Run::RT_Iteration)
        last_ms[r.run_name.str()] = ms;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  double get(const std::string& name) const {
    const auto it = median_ms.find(name);
    if (it != median_ms.end())
      return it->second;
    const auto jt = last_ms.find(name);
    return jt != last_ms.end() ? jt->second : -1.0;
  }
};

std::map<std::string, double> runOpen3d(int repetitions) {
  const char* env = std::getenv("MSF_OPEN3D_PYTHON");
  const std::string python = env ? env : "/usr/bin/python3";
  const std::string script = (fs::path(__FILE__).parent_path() / "open3d_tsdf.py").string();
  const std::string out = data().dir + "/open3d.json";
  std::ostringstream cmd;
  cmd << python << " " << script << " " << data().dir << " --voxel " << kVoxel << " --trunc " << kTrunc
      << " --max-depth " << kMaxDepth << " --repetitions " << repetitions << " > " << out;
  std::map<std::string, double> result;
  if (std::system(cmd.str().c_str()) != 0)
    return result;
  std::ifstream in(out);
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* key : {"integrate_ms_per_frame", "extract_ms", "vertices", "triangles"}) {
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
  if (!fs::is_directory(kittiDir() + "/odometry/sequences/04")) {
    std::fprintf(stderr, "bench_tsdf: error: KITTI sample not found in '%s' (set MSF_KITTI_DIR)\n", kittiDir().c_str());
    return 1;
  }
  data(); // SGBM once, before any timing
  MedianReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  const double ours_int = reporter.get("BM_TsdfIntegrate/lambda:0/manual_time");
  const double ours_int5 = reporter.get("BM_TsdfIntegrate/lambda:5/manual_time");
  const double ours_mesh = reporter.get("BM_MarchingCubesFull");
  std::printf("\nSide by side, KITTI odometry 04 frames 0-%d, SGBM depth, %.1f m voxels, %.1f m truncation, "
              "depth <= %.0f m (medians; the machine's 2 cores may be shared):\n",
              kFrames - 1, kVoxel, kTrunc, kMaxDepth);
  std::printf("  msfusion integrate, lambda 0: %8.1f ms/frame\n", ours_int);
  std::printf("  msfusion integrate, lambda 5: %8.1f ms/frame  (%.2fx lambda 0)\n", ours_int5, ours_int5 / ours_int);
  std::printf("  msfusion mesh (10-frame map): %8.1f ms\n", ours_mesh);
  const auto o3d = runOpen3d(5);
  if (o3d.count("integrate_ms_per_frame") && o3d.count("extract_ms")) {
    std::printf("  Open3D   integrate:           %8.1f ms/frame  -> msfusion %.1fx faster\n",
                o3d.at("integrate_ms_per_frame"), o3d.at("integrate_ms_per_frame") / ours_int);
    std::printf("  Open3D   mesh (10-frame map): %8.1f ms        -> msfusion %.1fx faster (%.0f vertices, %.0f triangles)\n",
                o3d.at("extract_ms"), o3d.at("extract_ms") / ours_mesh, o3d.count("vertices") ? o3d.at("vertices") : 0.0,
                o3d.count("triangles") ? o3d.at("triangles") : 0.0);
  } else {
    std::printf("  Open3D: not run (needs Debian's python3-open3d: make deps-bench)\n");
  }
  benchmark::Shutdown();
  return 0;
}
