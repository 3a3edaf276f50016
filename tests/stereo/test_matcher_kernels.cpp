// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// SemiGlobalMatcher's kernels (portable, AVX2, AVX-512BW) give the same disparities to the
// bit, for every kind of path (3-way, five paths, each with and without the ground prior),
// guided and unguided, on a noisy synthetic pair and on a KITTI frame.
#include <msf/io/image_io.h>
#include <msf/stereo/semi_global_matcher.h>

#include "stereo_scenes.h"
#include "test_support.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <string>
#include <tuple>
#include <vector>

namespace {

/// Runs one scope with the kernel named: "portable", "avx2" or "avx512".
struct KernelChoice {
  explicit KernelChoice(const std::string& kernel) {
    msf::SemiGlobalMatcher::setAvx2Enabled(kernel != "portable");
    msf::SemiGlobalMatcher::setAvx512Enabled(kernel == "avx512");
  }
  ~KernelChoice() {
    msf::SemiGlobalMatcher::setAvx2Enabled(true);
    msf::SemiGlobalMatcher::setAvx512Enabled(true);
  }
};

/// The kernels this CPU runs, the portable one first.
std::vector<std::string> kernels() {
  std::vector<std::string> out{"portable"};
  if (msf::SemiGlobalMatcher::usesAvx2())
    out.push_back("avx2");
  if (msf::SemiGlobalMatcher::usesAvx512())
    out.push_back("avx512");
  return out;
}

/// Hints every `step` rows, the truth moved by `offset_px` (disparity x 16, 0 = none).
cv::Mat rowHints(const cv::Mat& truth, int step, float offset_px) {
  cv::Mat hints = cv::Mat::zeros(truth.size(), CV_16SC1);
  for (int v = 0; v < truth.rows; v += step)
    for (int u = 0; u < truth.cols; ++u)
      hints.at<short>(v, u) = static_cast<short>(16.f * (truth.at<float>(v, u) + offset_px));
  return hints;
}

/// Disparities of `left`, `right` with every kernel; expects them equal and returns the count of matches.
int expectSameWithEveryKernel(const msf::SemiGlobalMatcher::Params& params, const cv::Mat& left, const cv::Mat& right,
                              const cv::Mat& hints, const std::string& what) {
  cv::Mat reference;
  for (const std::string& kernel : kernels()) {
    const KernelChoice choice(kernel);
    cv::Mat disparity;
    msf::SemiGlobalMatcher(params).compute(left, right, disparity, hints);
    if (reference.empty())
      reference = disparity;
    else
      EXPECT_EQ(cv::countNonZero(disparity != reference), 0) << kernel << " against portable, " << what;
  }
  return cv::countNonZero(reference >= 0);
}

/// (diagonal paths, ground prior, guided)
class MatcherKernels : public ::testing::TestWithParam<std::tuple<bool, bool, bool>> {
protected:
  msf::SemiGlobalMatcher::Params params() const {
    msf::SemiGlobalMatcher::Params p;
    p.diagonal_paths = std::get<0>(GetParam());
    p.p1_rise = std::get<1>(GetParam()) ? 75 : 0;
    if (std::get<2>(GetParam())) {
      p.guidance_gain = 400;
      p.guidance_max_penalty = 1500;
    }
    return p;
  }
  bool guided() const { return std::get<2>(GetParam()); }
};

TEST_P(MatcherKernels, SameDisparitiesOnANoisySyntheticPair) {
  // Noise, so that ties and ambiguous pixels occur.
  const cv::Size size(320, 160);
  auto pair = msf::test::makeSyntheticPair(size, 12.f, 30.f);
  cv::Mat noise(size, CV_8SC1);
  cv::randn(noise, 0, 8);
  cv::add(pair.right, noise, pair.right, cv::noArray(), CV_8U);
  const cv::Mat hints = guided() ? rowHints(pair.disparity, 4, 0.4f) : cv::Mat();
  // 32 and 64 fill AVX-512's vectors, 48 leaves 16 lanes of padding (AVX2 runs there).
  for (const int disparities : {32, 48, 64}) {
    msf::SemiGlobalMatcher::Params p = params();
    p.num_disparities = disparities;
    p.min_disparity = 3;
    const int matched = expectSameWithEveryKernel(p, pair.left, pair.right, hints, std::to_string(disparities));
    EXPECT_GT(matched, size.area() / 2) << disparities;
  }
}

TEST_P(MatcherKernels, SameDisparitiesOnAKittiFrame) {
  MSF_REQUIRE_KITTI();
  const std::string seq = msf::test::kittiDir() + "/odometry/sequences/04/";
  const cv::Mat left = msf::readImage(seq + "image_0/000004.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = msf::readImage(seq + "image_1/000004.png", cv::IMREAD_GRAYSCALE);
  cv::Mat hints;
  if (guided()) { // hints on every tenth row, from the 3-way match (what matters is that they vary)
    cv::Mat disparity;
    msf::SemiGlobalMatcher().compute(left, right, disparity);
    hints = cv::Mat::zeros(left.size(), CV_16SC1);
    for (int v = 0; v < left.rows; v += 10)
      disparity.row(v).copyTo(hints.row(v));
  }
  const int matched = expectSameWithEveryKernel(params(), left, right, hints, "odometry 04 frame 4");
  EXPECT_GT(matched, left.total() / 2);
}

std::string variantName(const ::testing::TestParamInfo<std::tuple<bool, bool, bool>>& info) {
  return std::string(std::get<0>(info.param) ? "FivePaths" : "ThreeWay") +
         (std::get<1>(info.param) ? "GroundPrior" : "") + (std::get<2>(info.param) ? "Guided" : "Unguided");
}

INSTANTIATE_TEST_SUITE_P(Paths, MatcherKernels,
                         ::testing::Combine(::testing::Bool(), ::testing::Bool(), ::testing::Bool()), variantName);

} // namespace
