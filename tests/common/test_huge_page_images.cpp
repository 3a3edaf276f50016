// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/huge_page_images.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace {
constexpr std::uintptr_t kHugePage = std::uintptr_t(2) << 20;

bool hugePagesAvailable() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(file, modes);
  return modes.find("[never]") == std::string::npos && !modes.empty();
}

/// The tools' allocator for the test's span; OpenCV's own afterwards, for the other tests.
class HugePageImages : public ::testing::Test {
protected:
  void SetUp() override {
    if (!hugePagesAvailable())
      GTEST_SKIP() << "this system has no transparent huge pages";
    msf::useHugePagesForLargeImages();
  }
  void TearDown() override { cv::Mat::setDefaultAllocator(cv::Mat::getStdAllocator()); }
};

bool onHugePageBoundary(const cv::Mat& image) { return reinterpret_cast<std::uintptr_t>(image.data) % kHugePage == 0; }
} // namespace

TEST_F(HugePageImages, ACameraSizedImageStartsOnA2MiBBoundaryAndKeepsItsValues) {
  cv::Mat depth(376, 1241, CV_32FC1);
  ASSERT_TRUE(depth.isContinuous());
  EXPECT_TRUE(onHugePageBoundary(depth));
  EXPECT_NE(depth.u->currAllocator, cv::Mat::getStdAllocator());
  cv::randu(depth, 0.f, 80.f);
  const cv::Mat copy = depth.clone();
  EXPECT_TRUE(onHugePageBoundary(copy));
  EXPECT_EQ(cv::norm(depth, copy, cv::NORM_INF), 0.0);
  EXPECT_EQ(depth.step[0], 1241 * sizeof(float));
  EXPECT_EQ(depth.at<float>(375, 1240), copy.at<float>(375, 1240));
}

TEST_F(HugePageImages, AVolumeOfThreeDimensionsHasOpenCvsStrides) {
  const int sizes[] = {4, 300, 300};
  cv::Mat volume(3, sizes, CV_32FC1, cv::Scalar(1.5f));
  EXPECT_TRUE(onHugePageBoundary(volume));
  EXPECT_EQ(volume.step[0], 300u * 300u * sizeof(float));
  EXPECT_EQ(volume.step[1], 300u * sizeof(float));
  EXPECT_EQ(volume.step[2], sizeof(float));
  EXPECT_EQ(cv::sum(volume)[0], 1.5 * 4 * 300 * 300);
}

TEST_F(HugePageImages, SmallImagesAndTheCallersOwnMemoryKeepOpenCvsAllocator) {
  const cv::Mat mask(376, 1241, CV_8UC1, cv::Scalar(255));
  EXPECT_EQ(mask.u->currAllocator, cv::Mat::getStdAllocator());
  std::vector<float> pixels(376 * 1241, 2.f);
  const cv::Mat wrapped(376, 1241, CV_32FC1, pixels.data());
  EXPECT_EQ(wrapped.data, reinterpret_cast<const uchar*>(pixels.data()));
  EXPECT_EQ(wrapped.u, nullptr);
  cv::Mat sum;
  cv::add(wrapped, wrapped, sum);
  EXPECT_TRUE(onHugePageBoundary(sum));
  EXPECT_EQ(sum.at<float>(200, 600), 4.f);
}

TEST_F(HugePageImages, AFreedImagesMappingIsReusedByTheNextImageOfItsSizeOnly) {
  // 4 MiB: a size no other test here allocates, so the cache holds no other mapping of it.
  cv::Mat first(1024, 1024, CV_32FC1, cv::Scalar(3.f));
  const uchar* address = first.data;
  cv::Mat alive(1024, 1024, CV_32FC1);
  EXPECT_NE(alive.data, address);
  first.release();
  const cv::Mat other_size(1024, 1536, CV_32FC1);
  EXPECT_NE(other_size.data, address);
  const cv::Mat next(1024, 1024, CV_32FC1, cv::Scalar(5.f));
  EXPECT_EQ(next.data, address);
  EXPECT_EQ(cv::sum(next)[0], 5.0 * 1024 * 1024);
}
