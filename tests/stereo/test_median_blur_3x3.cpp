// medianBlur3x3 against cv::medianBlur(src, dst, 3): identical on KITTI disparities and on
// synthetic images of every awkward size, including views into a larger image.
#include <msf/common/exceptions.h>
#include <msf/stereo/median_blur_3x3.h>

#include "post_filter_data.h"

#include <opencv2/imgproc.hpp>

#include <random>

namespace {

void expectSameAsOpenCv(const cv::Mat& src, const std::string& what) {
  cv::Mat ours, opencv;
  msf::medianBlur3x3(src, ours);
  cv::medianBlur(src, opencv, 3);
  ASSERT_EQ(ours.type(), CV_16SC1) << what;
  ASSERT_EQ(ours.size(), src.size()) << what;
  EXPECT_EQ(cv::countNonZero(ours != opencv), 0) << what;
}

TEST(MedianBlur3x3, KnownMedianOfAnImpulseAndAStep) {
  cv::Mat image(5, 6, CV_16SC1, cv::Scalar(100));
  image.at<short>(2, 2) = 30000;                     // an impulse: removed
  image(cv::Rect(4, 0, 2, 5)).setTo(cv::Scalar(-7)); // a two-column step: kept
  cv::Mat out;
  msf::medianBlur3x3(image, out);
  EXPECT_EQ(out.at<short>(2, 2), 100);
  EXPECT_EQ(out.at<short>(0, 3), 100);
  EXPECT_EQ(out.at<short>(0, 4), -7); // replicated border: the window holds six -7
  EXPECT_EQ(out.at<short>(4, 5), -7);
}

TEST(MedianBlur3x3, SameAsOpenCvOnRandomImagesOfAnySize) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> any(-32768, 32767);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(2, 1), cv::Size(1, 5), cv::Size(2, 2), cv::Size(7, 3),
                              cv::Size(33, 17), cv::Size(130, 61), cv::Size(1226, 37)}) {
    cv::Mat image(size, CV_16SC1);
    for (auto it = image.begin<short>(); it != image.end<short>(); ++it)
      *it = static_cast<short>(any(rng));
    expectSameAsOpenCv(image, "random " + std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  expectSameAsOpenCv(msf::test::syntheticFixedDisparity(cv::Size(301, 97), 5), "synthetic disparity");
}

TEST(MedianBlur3x3, SameAsOpenCvOnAViewIntoALargerImage) {
  const cv::Mat image = msf::test::syntheticFixedDisparity(cv::Size(200, 120), 9);
  expectSameAsOpenCv(image(cv::Rect(13, 7, 150, 90)), "view");
}

TEST(MedianBlur3x3, SameAsOpenCvOnKittiDisparities) {
  MSF_REQUIRE_KITTI();
  for (const int frame : {0, 7})
    expectSameAsOpenCv(msf::test::kittiFixedDisparity(frame), "KITTI frame " + std::to_string(frame));
}

TEST(MedianBlur3x3, RejectsOtherTypesAndInPlaceUse) {
  cv::Mat out;
  EXPECT_THROW(msf::medianBlur3x3(cv::Mat(), out), msf::InvalidInputError);
  EXPECT_THROW(msf::medianBlur3x3(cv::Mat(4, 4, CV_32FC1, cv::Scalar(1)), out), msf::InvalidInputError);
  cv::Mat image(4, 4, CV_16SC1, cv::Scalar(1));
  EXPECT_THROW(msf::medianBlur3x3(image, image), msf::InvalidInputError);
}

} // namespace
