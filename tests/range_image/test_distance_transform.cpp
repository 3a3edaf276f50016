// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The exact Euclidean distance to the nearest sample, against brute force.
#include <msf/common/exceptions.h>
#include <msf/range_image/distance_transform.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace {

struct Brute {
  cv::Mat distance;
  std::vector<cv::Point> samples;
};

Brute bruteForce(const cv::Mat& depth) {
  Brute b;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u)
      if (depth.at<float>(v, u) > 0.f)
        b.samples.emplace_back(u, v);
  b.distance.create(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& s : b.samples)
        best = std::min(best, std::hypot(s.x - u, s.y - v));
      b.distance.at<float>(v, u) = static_cast<float>(best);
    }
  return b;
}

cv::Mat randomSparse(int rows, int cols, double density, int seed) {
  cv::Mat d(rows, cols, CV_32FC1, cv::Scalar(0));
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  for (int v = 0; v < rows; ++v)
    for (int u = 0; u < cols; ++u)
      if (rng.uniform(0.0, 1.0) < density)
        d.at<float>(v, u) = 1.f + static_cast<float>(rng.uniform(0.0, 30.0));
  return d;
}

TEST(DistanceTransform, ExactAgainstBruteForceWithNearestSamples) {
  for (const double density : {0.002, 0.02, 0.2}) {
    const cv::Mat depth = randomSparse(61, 87, density, static_cast<int>(density * 1000));
    const Brute b = bruteForce(depth);
    ASSERT_FALSE(b.samples.empty());
    cv::Mat distance, nearest;
    msf::distanceToSamples(depth, distance, &nearest);
    ASSERT_EQ(distance.type(), CV_32FC1);
    ASSERT_EQ(nearest.type(), CV_32SC1);
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u) {
        EXPECT_NEAR(distance.at<float>(v, u), b.distance.at<float>(v, u), 1e-4f) << u << "," << v;
        const int k = nearest.at<int>(v, u);
        ASSERT_GE(k, 0);
        const int nu = k % depth.cols, nv = k / depth.cols;
        EXPECT_GT(depth.at<float>(nv, nu), 0.f) << "nearest of " << u << "," << v << " is not a sample";
        EXPECT_NEAR(std::hypot(nu - u, nv - v), b.distance.at<float>(v, u), 1e-4);
      }
  }
}

TEST(DistanceTransform, ExactOnAScanLikePattern) {
  // Wavy rings a few rows apart below an empty top, as a LiDAR scan projects: the search
  // over rows goes deep above the first ring and stays shallow between rings.
  cv::Mat depth(90, 150, CV_32FC1, cv::Scalar(0));
  cv::RNG rng(7);
  for (int ring = 0; ring < 12; ++ring)
    for (int u = 0; u < depth.cols; ++u)
      if (rng.uniform(0.0, 1.0) < 0.7) {
        const int v = 30 + 5 * ring + static_cast<int>(std::lround(2.0 * std::sin(0.05 * u + ring)));
        depth.at<float>(v, u) = 5.f;
      }
  const Brute b = bruteForce(depth);
  cv::Mat distance, nearest;
  msf::distanceToSamples(depth, distance, &nearest, 2);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      ASSERT_NEAR(distance.at<float>(v, u), b.distance.at<float>(v, u), 1e-4f) << u << "," << v;
      const int k = nearest.at<int>(v, u);
      ASSERT_NEAR(std::hypot(k % depth.cols - u, k / depth.cols - v), b.distance.at<float>(v, u), 1e-4);
    }
}

TEST(DistanceTransform, ZeroOnSamplesInfinityWithoutAny) {
  cv::Mat depth(5, 7, CV_32FC1, cv::Scalar(0)), distance, nearest;
  msf::distanceToSamples(depth, distance, &nearest);
  for (int v = 0; v < 5; ++v)
    for (int u = 0; u < 7; ++u) {
      EXPECT_TRUE(std::isinf(distance.at<float>(v, u)));
      EXPECT_EQ(nearest.at<int>(v, u), -1);
    }
  depth.at<float>(4, 6) = 3.f;
  msf::distanceToSamples(depth, distance);
  EXPECT_EQ(distance.at<float>(4, 6), 0.f);
  EXPECT_FLOAT_EQ(distance.at<float>(0, 0), static_cast<float>(std::hypot(6.0, 4.0)));
}

TEST(DistanceTransform, SameResultForAnyThreadCount) {
  const cv::Mat depth = randomSparse(150, 233, 0.01, 3);
  cv::Mat reference, near_reference;
  msf::distanceToSamples(depth, reference, &near_reference, 1);
  for (int threads : {2, 4}) {
    cv::Mat distance, nearest;
    msf::distanceToSamples(depth, distance, &nearest, threads);
    EXPECT_EQ(0, std::memcmp(distance.data, reference.data, reference.total() * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(nearest.data, near_reference.data, reference.total() * sizeof(int)));
  }
}

TEST(DistanceTransform, RejectsWrongImages) {
  cv::Mat distance;
  EXPECT_THROW(msf::distanceToSamples(cv::Mat(3, 3, CV_8UC1), distance), msf::InvalidInputError);
  EXPECT_THROW(msf::distanceToSamples(cv::Mat(), distance), msf::InvalidInputError);
  EXPECT_THROW(msf::distanceToSamples(cv::Mat(1, 9000, CV_32FC1, cv::Scalar(0)), distance), msf::InvalidInputError);
}

} // namespace
