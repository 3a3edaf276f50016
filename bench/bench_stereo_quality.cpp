// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The stereo matcher alone, unguided, as msf_stereo runs it (SgbmStereo, the stereo section's
// defaults: 128 disparities, block 5), in each mode side by side in one run: OpenCV's
// StereoSGBM 3-way and 5-path (engine opencv), the native engine's sgbm_3way, sgbm (five
// paths) and ground_3way (the default unguided_mode). Per sequence: on KITTI, protocol 2 (the
// held-out rings' pixels of camera 0); on a synthetic sequence (msf_synth), protocol 3 (every
// pixel of gt/disp_0, the KITTI devkit's D1, and its background and foreground). Rows:
// coverage, D1 with a missing estimate bad, D1 on estimates, and the median time of
// SgbmStereo::computeDisparity per frame with its ratio to OpenCV's 3-way and to the native
// five paths of the same run.
//
//   bench_stereo_quality SEQUENCE_DIR[:a:b] ...    (frames a..b, default all)
#include <msf/evaluation/disparity_metrics.h>
#include <msf/evaluation/holdout.h>
#include <msf/io/image_io.h>
#include <msf/io/sequence.h>
#include <msf/stereo/sgbm_stereo.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Row {
  const char* name;
  const char* engine;
  const char* mode;
};

/// The first row is the reference of the first ratio, the fourth of the second.
const Row kRows[] = {{"opencv sgbm_3way", "opencv", "sgbm_3way"},
                     {"opencv sgbm", "opencv", "sgbm"},
                     {"native sgbm_3way", "native", "sgbm_3way"},
                     {"native sgbm", "native", "sgbm"},
                     {"native ground_3way", "native", "ground_3way"}};
constexpr std::size_t kRowCount = sizeof kRows / sizeof kRows[0];
constexpr std::size_t kFivePaths = 3;

std::shared_ptr<msf::SgbmStereo> stereoFor(const Row& row, const msf::Calibration& calibration) {
  msf::SgbmConfig config;
  config.engine = row.engine;
  config.unguided_mode = row.mode;
  config.guidance = "none";
  auto stereo = std::make_shared<msf::SgbmStereo>(config);
  stereo->setCalibration(calibration);
  return stereo;
}

/// Milliseconds of one computeDisparity of the pair.
double match(msf::SgbmStereo& stereo, const cv::Mat& left, const cv::Mat& right) {
  stereo.setInputImages(left, right);
  const auto start = std::chrono::steady_clock::now();
  stereo.computeDisparity();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Scores {
  double coverage = 0, d1 = 0, d1_estimated = 0, ms = 0;
};

void printTable(const std::string& title, const Scores (&scores)[kRowCount]) {
  std::printf("\n%s\n  %-20s %8s %8s %8s %9s %9s %9s\n", title.c_str(), "matcher", "coverage", "D1", "D1 est",
              "ms/frame", "/ opencv", "/ 5 paths");
  for (std::size_t m = 0; m < kRowCount; ++m)
    std::printf("  %-20s %8.4f %7.2f%% %7.2f%% %9.1f %9.3f %9.3f\n", kRows[m].name, scores[m].coverage,
                100 * scores[m].d1, 100 * scores[m].d1_estimated, scores[m].ms, scores[m].ms / scores[0].ms,
                scores[m].ms / scores[kFivePaths].ms);
}

/// Protocol 3: every pixel of gt/disp_0, split by gt/obj_map_0.
void groundTruth(const msf::Sequence& sequence, const std::vector<std::size_t>& frames) {
  std::vector<std::shared_ptr<msf::SgbmStereo>> stereo;
  for (const Row& row : kRows)
    stereo.push_back(stereoFor(row, sequence.calibration()));
  msf::DisparityEvaluation evaluation[kRowCount];
  std::vector<double> times[kRowCount];
  const std::string gt = sequence.groundTruthDir();
  for (const std::size_t i : frames) {
    const msf::Frame frame = sequence.load(i, false);
    const std::string name = sequence.frameName(i);
    const cv::Mat truth = msf::readKittiDisparityPng(gt + "/disp_0/" + name + ".png");
    const cv::Mat objects = msf::readImage(gt + "/obj_map_0/" + name + ".png", cv::IMREAD_UNCHANGED);
    for (std::size_t m = 0; m < kRowCount; ++m) {
      times[m].push_back(match(*stereo[m], frame.left, frame.right));
      evaluation[m] += msf::evaluateDisparity(truth, stereo[m]->getDisparity(), objects);
    }
  }
  Scores scores[kRowCount];
  for (std::size_t m = 0; m < kRowCount; ++m)
    scores[m] = {evaluation[m].all.density(), evaluation[m].all.d1(), evaluation[m].all.d1Estimated(),
                 median(times[m])};
  printTable(sequence.directory() + ", " + std::to_string(frames.size()) + " frames (protocol 3, all pixels)", scores);
  std::printf("  %-20s %18s %18s\n", "D1 (D1 est)", "background", "foreground");
  for (std::size_t m = 0; m < kRowCount; ++m)
    std::printf("  %-20s %8.2f%% (%5.2f%%) %8.2f%% (%5.2f%%)\n", kRows[m].name, 100 * evaluation[m].background.d1(),
                100 * evaluation[m].background.d1Estimated(), 100 * evaluation[m].foreground.d1(),
                100 * evaluation[m].foreground.d1Estimated());
}

/// Protocol 2: the held-out rings.
void holdout(const msf::Sequence& sequence, const std::vector<std::size_t>& frames) {
  msf::HoldoutEvaluation evaluation;
  for (const Row& row : kRows) {
    auto stereo = stereoFor(row, sequence.calibration());
    evaluation.addMethod(row.name, [stereo](const msf::HoldoutInput& in) {
      stereo->setInputImages(in.left, in.right);
      stereo->computeDisparity();
      return stereo->getDepth();
    });
  }
  const auto results = evaluation.run(sequence, frames);
  Scores scores[kRowCount];
  for (std::size_t m = 0; m < kRowCount; ++m)
    scores[m] = {results[m].metrics.coverage, results[m].metrics.d1_all, results[m].metrics.d1_estimated,
                 results[m].median_ms};
  printTable(sequence.directory() + ", " + std::to_string(frames.size()) + " frames (protocol 2, held-out rings)",
             scores);
}

} // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_stereo_quality SEQUENCE_DIR[:a:b] ...\n");
    return 2;
  }
  try {
    for (int a = 1; a < argc; ++a) {
      std::string dir = argv[a];
      msf::FrameRange range;
      const auto colon = dir.find(':');
      if (colon != std::string::npos) {
        range = msf::FrameRange::parse(dir.substr(colon + 1));
        dir = dir.substr(0, colon);
      }
      const msf::Sequence sequence(dir);
      const auto frames = sequence.indices(range);
      if (sequence.groundTruthDir().empty())
        holdout(sequence, frames);
      else
        groundTruth(sequence, frames);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_stereo_quality: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
