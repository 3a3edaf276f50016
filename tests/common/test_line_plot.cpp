// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/line_plot.h>

#include "test_support.h"

#include <opencv2/core.hpp>

namespace {

int countColour(const cv::Mat& image, const cv::Vec3b& colour) {
  int n = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u)
      n += image.at<cv::Vec3b>(v, u) == colour;
  return n;
}

TEST(LinePlot, DrawsEachSeriesInItsColour) {
  msf::LinePlot plot("time per frame", "frame", "ms");
  plot.addSeries("stereo", {0, 1, 2, 3}, {40, 42, 41, 39});
  plot.addSeries("fusion", {0, 1, 2, 3}, {2, 2.5, 2, 1.5});
  plot.addReferenceLine(33, "target");
  const cv::Mat image = plot.render(640, 400);
  EXPECT_EQ(image.size(), cv::Size(640, 400));
  EXPECT_GT(countColour(image, cv::Vec3b(180, 119, 31)), 100); // first series
  EXPECT_GT(countColour(image, cv::Vec3b(14, 127, 255)), 100); // second series
}

TEST(LinePlot, MismatchedOrEmptySeriesIsAnError) {
  msf::LinePlot plot("t", "x", "y");
  EXPECT_THROW(plot.addSeries("bad", {1, 2}, {1}), msf::InvalidInputError);
  EXPECT_THROW(plot.render(), msf::InvalidInputError);
  plot.setLogY(true);
  plot.addSeries("nonpositive", {1, 2}, {0, -1});
  EXPECT_THROW(plot.render(), msf::InvalidInputError);
}

} // namespace
