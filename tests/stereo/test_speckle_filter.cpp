// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// filterSpecklesParallel against cv::filterSpeckles: identical on KITTI disparities and on
// synthetic images, whatever the number of threads; hand-made regions with known fates,
// among them regions that cross many row bands.
#include <msf/common/exceptions.h>
#include <msf/stereo/speckle_filter.h>

#include "post_filter_data.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

namespace {

constexpr short kNone = -16;

void expectSameAsOpenCv(const cv::Mat& image, int new_value, int max_size, int max_diff, const std::string& what) {
  cv::Mat ours = image.clone(), opencv = image.clone(), buffer;
  msf::filterSpecklesParallel(ours, new_value, max_size, max_diff, buffer);
  cv::filterSpeckles(opencv, new_value, max_size, max_diff);
  EXPECT_EQ(cv::countNonZero(ours != opencv), 0) << what;
}

/// `image` filtered by ours, with 100-pixel regions and a speckle range of 2 px (x16).
cv::Mat filtered(const cv::Mat& image, int max_size = 100, int max_diff = 32) {
  cv::Mat out = image.clone(), buffer;
  msf::filterSpecklesParallel(out, kNone, max_size, max_diff, buffer);
  return out;
}

TEST(SpeckleFilter, RegionOfAtMostMaxSizePixelsIsCleared) {
  cv::Mat image(40, 50, CV_16SC1, cv::Scalar(320));
  image(cv::Rect(10, 10, 5, 4)).setTo(cv::Scalar(800)); // 20 pixels, 30 px off the background
  image(cv::Rect(30, 20, 7, 3)).setTo(cv::Scalar(810)); // 21 pixels
  image(cv::Rect(30, 30, 4, 4)).setTo(cv::Scalar(335)); // within 2 px of the background: joins it
  const cv::Mat out = filtered(image, 20);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(10, 10, 5, 4)) != kNone), 0);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(30, 20, 7, 3)) != 810), 0);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(30, 30, 4, 4)) != 335), 0);
  EXPECT_EQ(cv::countNonZero(out == kNone), 20);
  expectSameAsOpenCv(image, kNone, 20, 32, "blocks");
}

TEST(SpeckleFilter, HolesSeparateRegionsAndStayHoles) {
  cv::Mat image(30, 30, CV_16SC1, cv::Scalar(480));
  image.col(15).setTo(cv::Scalar(kNone)); // splits the plane into 30x15 and 30x14
  const cv::Mat out = filtered(image, 430);
  EXPECT_EQ(cv::countNonZero(out.colRange(0, 15) != 480), 0);      // 450 pixels: kept
  EXPECT_EQ(cv::countNonZero(out.colRange(16, 30) != kNone), 0);   // 420 pixels: cleared
  EXPECT_EQ(cv::countNonZero(out.col(15) != kNone), 0);
}

TEST(SpeckleFilter, RegionsAcrossManyRowBandsAreJoined) {
  // A one-pixel-wide snake down and up the image through every row band: 4 columns of 200
  // rows joined at alternate ends, 803 pixels in one region; beside it, separate columns.
  cv::Mat image(200, 20, CV_16SC1, cv::Scalar(kNone));
  for (int c = 0; c < 4; ++c) {
    image.col(2 * c).setTo(cv::Scalar(160 + 16 * c)); // each column 1 px from the next
    if (c < 3)
      image.at<short>(c % 2 == 0 ? 199 : 0, 2 * c + 1) = static_cast<short>(168 + 16 * c);
  }
  image.col(12).setTo(cv::Scalar(500)); // 200 pixels on its own
  for (const int max_size : {802, 803}) {
    const cv::Mat out = filtered(image, max_size);
    const int snake_left = cv::countNonZero(out.colRange(0, 8) != kNone);
    EXPECT_EQ(snake_left, max_size < 803 ? 803 : 0) << max_size;
    EXPECT_EQ(cv::countNonZero(out.col(12) == kNone), 200) << max_size;
    expectSameAsOpenCv(image, kNone, max_size, 32, "snake " + std::to_string(max_size));
  }
}

TEST(SpeckleFilter, SameAsOpenCvOnSyntheticImages) {
  unsigned seed = 1;
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(9, 1), cv::Size(1, 60), cv::Size(123, 77), cv::Size(640, 190)})
    for (const int max_size : {0, 1, 10, 100})
      for (const int max_diff : {0, 16, 32}) {
        const cv::Mat image = msf::test::syntheticFixedDisparity(size, seed++, 0.1, kNone);
        expectSameAsOpenCv(image, kNone, max_size, max_diff,
                           "size " + std::to_string(size.width) + "x" + std::to_string(size.height) + " max_size " +
                               std::to_string(max_size) + " max_diff " + std::to_string(max_diff));
      }
  // Another no-match value, one that also occurs as a disparity nowhere else.
  expectSameAsOpenCv(msf::test::syntheticFixedDisparity(cv::Size(300, 100), 99, 0.2, 0), 0, 50, 16, "new value 0");
}

TEST(SpeckleFilter, SameAsOpenCvWhateverTheNumberOfThreads) {
  const cv::Mat image = msf::test::syntheticFixedDisparity(cv::Size(500, 300), 21, 0.15, kNone);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const cv::Mat one = filtered(image);
  cv::setNumThreads(threads);
  EXPECT_EQ(cv::countNonZero(one != filtered(image)), 0);
  expectSameAsOpenCv(image, kNone, 100, 32, "threads");
}

TEST(SpeckleFilter, SameAsOpenCvOnKittiDisparities) {
  MSF_REQUIRE_KITTI();
  for (const int frame : {0, 3, 9}) {
    const cv::Mat fixed = msf::test::kittiFixedDisparity(frame);
    // Not a vacuous comparison: thousands of pixels are speckles (5270 in frame 0).
    EXPECT_GT(cv::countNonZero(filtered(fixed) != fixed), 1000) << frame;
    for (const int max_size : {100, 400})
      expectSameAsOpenCv(fixed, kNone, max_size, 32,
                         "KITTI frame " + std::to_string(frame) + " max_size " + std::to_string(max_size));
  }
}

TEST(SpeckleFilter, RejectsOtherTypes) {
  cv::Mat buffer;
  cv::Mat empty, floats(4, 4, CV_32FC1, cv::Scalar(1));
  EXPECT_THROW(msf::filterSpecklesParallel(empty, 0, 10, 1, buffer), msf::InvalidInputError);
  EXPECT_THROW(msf::filterSpecklesParallel(floats, 0, 10, 1, buffer), msf::InvalidInputError);
}

} // namespace
