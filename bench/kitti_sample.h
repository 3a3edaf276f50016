// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The KITTI sample the benchmarks time: odometry sequence 04, frames 0-9 (../shared/data/kitti;
// KITTI data is never copied into the repository).
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>

#include <opencv2/core/utility.hpp>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace msf::bench {

/// The sample's folder: MSF_KITTI_DIR in the environment, else the path CMake compiled in.
inline std::string kittiDir() {
  const char* env = std::getenv("MSF_KITTI_DIR");
  return env ? env : MSF_KITTI_DIR;
}

/// Odometry sequence 04 of the sample; without it, a clear error and exit code 1.
inline Sequence kittiSequence() {
  try {
    return Sequence(kittiDir() + "/odometry/sequences/04");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: no KITTI sample: %s (set MSF_KITTI_DIR)\n", e.what());
    std::exit(1);
  }
}

/// Frames of it that the benchmarks time.
constexpr std::size_t kFrames = 10;

/// The scans of those frames, as the reader gives them.
inline std::vector<pcl::PointCloud<pcl::PointXYZI>> kittiScans(const Sequence& sequence) {
  std::vector<pcl::PointCloud<pcl::PointXYZI>> scans;
  for (std::size_t i = 0; i < kFrames && i < sequence.size(); ++i) {
    scans.emplace_back();
    loadVelodyneBin(sequence.scanPath(i), scans.back());
  }
  return scans;
}

/// OpenCV's parallel loops on the calling thread while it lives: per-core costs, steadier
/// than wall time on a machine shared with other work.
class OneThread {
public:
  OneThread() : threads_(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~OneThread() { cv::setNumThreads(threads_); }
  OneThread(const OneThread&) = delete;
  OneThread& operator=(const OneThread&) = delete;

private:
  int threads_;
};

} // namespace msf::bench
