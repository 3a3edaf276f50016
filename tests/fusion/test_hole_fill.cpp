// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/hole_fill.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <limits>
#include <string>

using namespace msf;

namespace {

/// A wall 10 m away on the left half, a car 5 m away on the right half, weight 100 everywhere.
struct Scene {
  cv::Mat depth{40, 60, CV_32FC1, cv::Scalar(10.f)};
  cv::Mat weight{40, 60, CV_32FC1, cv::Scalar(100.f)};
  cv::Mat free_weight{40, 60, CV_32FC1, cv::Scalar(100.f)};
  Scene() { depth.colRange(30, 60).setTo(5.f); }
  void hole(const cv::Rect& r) {
    depth(r).setTo(0.f);
    weight(r).setTo(0.f);
    free_weight(r).setTo(0.f);
  }
};

} // namespace

TEST(HoleFill, ASmallHoleTakesTheNearestDepthAtWeightZero) {
  Scene s;
  s.hole(cv::Rect(10, 10, 6, 3));                           // inside the wall
  s.depth.at<float>(20, 12) = std::numeric_limits<float>::quiet_NaN(); // NaN is no depth
  const cv::Mat filled = fillSmallHoles(s.depth, s.weight, s.free_weight, cv::Mat(), 8);
  EXPECT_EQ(cv::countNonZero(filled), 6 * 3 + 1);
  EXPECT_EQ(cv::countNonZero(s.depth.colRange(0, 30) != 10.f), 0); // the wall's, NaN's pixel too
  EXPECT_FLOAT_EQ(s.depth.at<float>(11, 12), 10.f);
  EXPECT_FLOAT_EQ(s.depth.at<float>(20, 12), 10.f);
  EXPECT_FLOAT_EQ(s.weight.at<float>(11, 12), 0.f);       // a guess: the map does not integrate it
  EXPECT_FLOAT_EQ(s.free_weight.at<float>(11, 12), 0.f);
  EXPECT_FLOAT_EQ(s.weight.at<float>(5, 5), 100.f);         // what had a depth is untouched
}

TEST(HoleFill, AtAnEdgeEachSideTakesItsNearerSurfaceAndATieTheNearerDepth) {
  Scene s;
  s.hole(cv::Rect(26, 5, 7, 1)); // columns 26-32 of row 5: wall 25 on the left, car 33 on the right
  fillSmallHoles(s.depth, s.weight, s.free_weight, cv::Mat(), 8);
  for (int u = 26; u <= 28; ++u)
    EXPECT_FLOAT_EQ(s.depth.at<float>(5, u), 10.f) << u;
  EXPECT_FLOAT_EQ(s.depth.at<float>(5, 29), 5.f); // 4 px from both: the nearer surface, the car
  for (int u = 30; u <= 32; ++u)
    EXPECT_FLOAT_EQ(s.depth.at<float>(5, u), 5.f) << u;
}

TEST(HoleFill, AHoleWiderThanTheRadiusKeepsItsMiddleAndColumnsFillWhatRowsCannot) {
  Scene s;
  s.hole(cv::Rect(0, 10, 30, 1)); // a whole row of the wall: no depth along it within reach
  s.hole(cv::Rect(2, 20, 24, 1)); // 24 px wide: rows reach 8 px from each end
  fillSmallHoles(s.depth, s.weight, s.free_weight, cv::Mat(), 8);
  EXPECT_FLOAT_EQ(s.depth.at<float>(10, 0), 10.f); // by its column: rows 9 and 11
  EXPECT_FLOAT_EQ(s.depth.at<float>(20, 13), 10.f); // the middle, by its column too
  s.hole(cv::Rect(0, 0, 30, 40)); // the whole wall gone: 30 px from the car
  const cv::Mat filled = fillSmallHoles(s.depth, s.weight, s.free_weight, cv::Mat(), 8);
  EXPECT_FLOAT_EQ(s.depth.at<float>(20, 25), 5.f); // 5 px from the car
  EXPECT_EQ(s.depth.at<float>(20, 10), 0.f);       // 20 px from it: still a hole
  EXPECT_EQ(filled.at<std::uint8_t>(20, 10), 0);
}

TEST(HoleFill, TheExcludedSkyStaysEmptyAndBlocksTheFill) {
  Scene s;
  s.hole(cv::Rect(0, 0, 60, 8)); // the top rows: sky above the wall and the car
  cv::Mat sky(s.depth.size(), CV_8UC1, cv::Scalar(0));
  sky.rowRange(0, 6).setTo(255);
  s.hole(cv::Rect(10, 20, 3, 1));
  sky.at<std::uint8_t>(20, 11) = 255; // a sky pixel between the hole's two halves
  fillSmallHoles(s.depth, s.weight, s.free_weight, sky, 8);
  EXPECT_EQ(cv::countNonZero(s.depth.rowRange(0, 6)), 0);
  EXPECT_FLOAT_EQ(s.depth.at<float>(7, 5), 10.f); // below the sky, from the wall under it
  EXPECT_EQ(s.depth.at<float>(20, 11), 0.f);
  EXPECT_FLOAT_EQ(s.depth.at<float>(20, 10), 10.f);
  EXPECT_FLOAT_EQ(s.depth.at<float>(20, 12), 10.f);
}

TEST(HoleFill, ARadiusOfZeroChangesNothingAndBadImagesAreRefused) {
  Scene s;
  s.hole(cv::Rect(10, 10, 2, 2));
  const cv::Mat before = s.depth.clone();
  EXPECT_EQ(cv::countNonZero(fillSmallHoles(s.depth, s.weight, s.free_weight, cv::Mat(), 0)), 0);
  EXPECT_EQ(cv::countNonZero(s.depth != before), 0);
  cv::Mat small_weight(10, 10, CV_32FC1, cv::Scalar(1.f));
  try {
    fillSmallHoles(s.depth, small_weight, s.free_weight, cv::Mat(), 8);
    FAIL() << "a weight of another size was taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("the weight is not CV_32FC1 of the depth's size"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(cv::countNonZero(s.depth != before), 0); // nothing changed
  cv::Mat wrong_mask(s.depth.size(), CV_32FC1, cv::Scalar(0.f));
  EXPECT_THROW(fillSmallHoles(s.depth, s.weight, s.free_weight, wrong_mask, 8), InvalidInputError);
}

TEST(HoleFill, ADepthWithoutWeightsFillsAsTheWeightedOne) {
  Scene weighted, bare;
  weighted.hole(cv::Rect(25, 5, 10, 4)); // across the wall's edge with the car
  bare.hole(cv::Rect(25, 5, 10, 4));
  const cv::Mat by_weighted = fillSmallHoles(weighted.depth, weighted.weight, weighted.free_weight, cv::Mat(), 8);
  cv::Mat none; // no weights: the depth alone is filled
  const cv::Mat by_bare = fillSmallHoles(bare.depth, none, none, cv::Mat(), 8);
  EXPECT_EQ(cv::countNonZero(by_bare), 10 * 4);
  EXPECT_EQ(cv::countNonZero(by_bare != by_weighted), 0);
  EXPECT_EQ(cv::countNonZero(bare.depth != weighted.depth), 0);
  cv::Mat wrong_mask(bare.depth.size(), CV_32FC1, cv::Scalar(0.f));
  EXPECT_THROW(fillSmallHoles(bare.depth, none, none, wrong_mask, 8), InvalidInputError);
}
