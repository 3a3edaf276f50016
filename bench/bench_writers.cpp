// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The cost of writing checked to the end (msf/common/checked_write.h) beside PCL's own writers,
// in the same run, into /dev/shm (the CPU's cost, not a disk's): an organized KITTI-sized
// cloud as a binary compressed .pcd (PCL's file writer maps the file; saveCloud writes the same
// points by writeCompressedPcd, compressed in pieces on every core, into a checked stream) and a
// mesh as a binary .ply (PCL's writer alone;
// saveMesh, the same writer through the checked pipe). 10 repetitions of 5 writes; median and
// minimum over the repetitions.
//
//   bench_writers [--benchmark_filter=Mesh]   (MSF_KITTI_DIR overrides the compiled-in path)
#include "kitti_sample.h"

#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace {

/// Frame 0's colour image as an organized cloud at a depth that follows its grey values (a
/// surface as smooth and as textured as a stereo depth), and a mesh of 500 x 500 vertices.
struct Data {
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  pcl::PolygonMesh mesh;
  Data() {
    const msf::Sequence sequence = msf::bench::kittiSequence();
    const cv::Mat colour = msf::readImage(sequence.imagePath(2, 0), cv::IMREAD_COLOR);
    cloud.width = static_cast<std::uint32_t>(colour.cols);
    cloud.height = static_cast<std::uint32_t>(colour.rows);
    cloud.resize(cloud.width * cloud.height);
    for (int v = 0; v < colour.rows; ++v)
      for (int u = 0; u < colour.cols; ++u) {
        const cv::Vec3b c = colour.at<cv::Vec3b>(v, u);
        pcl::PointXYZRGB& p = cloud.at(u, v);
        p.z = 5.f + 0.1f * c[1];
        p.x = (u - 600.f) * p.z / 700.f, p.y = (v - 180.f) * p.z / 700.f;
        p.b = c[0], p.g = c[1], p.r = c[2];
      }
    const int n = 500;
    pcl::PointCloud<pcl::PointXYZRGB> vertices;
    for (int v = 0; v < n; ++v)
      for (int u = 0; u < n; ++u)
        vertices.push_back(cloud.at(u % colour.cols, v % colour.rows));
    pcl::toPCLPointCloud2(vertices, mesh.cloud);
    for (int v = 0; v + 1 < n; ++v)
      for (int u = 0; u + 1 < n; ++u) {
        const int a = v * n + u;
        pcl::Vertices t1, t2;
        t1.vertices = {a, a + 1, a + n};
        t2.vertices = {a + 1, a + n + 1, a + n};
        mesh.polygons.push_back(t1);
        mesh.polygons.push_back(t2);
      }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

const std::string kFolder = "/dev/shm";

void BM_CloudPclFileWriter(benchmark::State& state) {
  const std::string path = kFolder + "/bench_writers_pcl.pcd";
  for (auto _ : state)
    pcl::PCDWriter().writeBinaryCompressed(path, data().cloud);
  std::remove(path.c_str());
}

void BM_CloudSaveCloudChecked(benchmark::State& state) {
  const std::string path = kFolder + "/bench_writers_msf.pcd";
  for (auto _ : state)
    msf::saveCloud(path, data().cloud);
  std::remove(path.c_str());
}

void BM_MeshPclPlyWriter(benchmark::State& state) {
  const std::string path = kFolder + "/bench_writers_pcl.ply";
  for (auto _ : state)
    pcl::io::savePLYFileBinary(path, data().mesh);
  std::remove(path.c_str());
}

void BM_MeshSaveMeshChecked(benchmark::State& state) {
  const std::string path = kFolder + "/bench_writers_msf.ply";
  for (auto _ : state)
    msf::saveMesh(path, data().mesh);
  std::remove(path.c_str());
}

double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

} // namespace

#define MSF_WRITER_BENCH(name)                                                                                 \
  BENCHMARK(name)                                                                                              \
      ->Unit(benchmark::kMillisecond)                                                                          \
      ->UseRealTime()                                                                                          \
      ->Iterations(5)                                                                                          \
      ->Repetitions(10)                                                                                        \
      ->ReportAggregatesOnly(true)                                                                             \
      ->ComputeStatistics("min", minimum)

MSF_WRITER_BENCH(BM_CloudPclFileWriter);
MSF_WRITER_BENCH(BM_CloudSaveCloudChecked);
MSF_WRITER_BENCH(BM_MeshPclPlyWriter);
MSF_WRITER_BENCH(BM_MeshSaveMeshChecked);
BENCHMARK_MAIN();
