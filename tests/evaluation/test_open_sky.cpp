// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Evaluation protocol 6: the sky mask on drawn images with known answers and on a hand-checked
// KITTI frame, and the share of it a mesh covers.
#include <msf/common/exceptions.h>
#include <msf/evaluation/open_sky_coverage.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/sequence.h>
#include <msf/range_image/lidar_projector.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

using namespace msf;

namespace {

constexpr int kWidth = 200, kHeight = 100;

/// A drawn street scene (BGR): a blue sky with a brightening gradient over rows 0-59, a
/// textured green crown reaching the top edge over columns 20-59, a white wall over columns
/// 140-179 from row 30, a blue patch walled in by texture at rows 40-49 of columns 90-109,
/// and a grey road from row 60.
cv::Mat drawnScene() {
  cv::Mat image(kHeight, kWidth, CV_8UC3);
  for (int v = 0; v < kHeight; ++v)
    image.row(v).setTo(v < 60 ? cv::Scalar(230, 170 + v / 2, 120 + v / 2) : cv::Scalar(100, 100, 100));
  cv::Mat crown = image(cv::Rect(20, 0, 40, 50));
  cv::randu(crown, cv::Scalar(20, 60, 20), cv::Scalar(90, 200, 90));
  image(cv::Rect(140, 30, 40, 30)).setTo(cv::Scalar(235, 235, 235));
  cv::Mat fence = image(cv::Rect(80, 30, 40, 30));
  cv::randu(fence, cv::Scalar(0, 0, 0), cv::Scalar(255, 255, 255));
  image(cv::Rect(90, 40, 20, 10)).setTo(cv::Scalar(230, 190, 140));
  return image;
}

/// LiDAR returns on the road, the crown's lower half and the wall's lower rows.
cv::Mat drawnReturns() {
  cv::Mat returns(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  for (int v = 62; v < kHeight; v += 4)
    returns.row(v).setTo(10.f);
  for (int v = 26; v < 60; v += 4) {
    returns(cv::Rect(20, v, 40, 1)).setTo(8.f);
    returns(cv::Rect(80, v, 40, 1)).setTo(9.f);
    returns(cv::Rect(140, v, 40, 1)).setTo(12.f);
  }
  return returns;
}

bool sky(const cv::Mat& mask, int u, int v) { return mask.at<std::uint8_t>(v, u) != 0; }

PinholeCamera camera() {
  PinholeCamera c;
  c.width = kWidth, c.height = kHeight;
  c.fx = c.fy = 100.f;
  c.cx = 99.5f, c.cy = 49.5f;
  return c;
}

/// A square facing the camera at depth z over world x in [x0, x1], y in [y0, y1].
TriangleMesh square(float x0, float x1, float y0, float y1, float z) {
  TriangleMesh mesh;
  mesh.vertices = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

} // namespace

TEST(SkyMask, KeepsTheOpenSkyAndNothingBelowOrAroundIt) {
  const cv::Mat mask = SkyMask().compute(drawnScene(), drawnReturns());
  ASSERT_EQ(mask.type(), CV_8UC1);
  EXPECT_TRUE(sky(mask, 100, 5));    // top centre
  EXPECT_TRUE(sky(mask, 120, 20));   // above the fence's returns
  EXPECT_TRUE(sky(mask, 190, 10));   // the top right corner's sky
  EXPECT_FALSE(sky(mask, 40, 5));    // the crown: textured
  EXPECT_FALSE(sky(mask, 160, 40));  // the white wall: under returns
  EXPECT_FALSE(sky(mask, 100, 45));  // blue, blank, but walled in by the fence and under its returns
  EXPECT_FALSE(sky(mask, 100, 80));  // the road
  EXPECT_FALSE(sky(mask, 62, 10));   // within the border of the crown's edge
  EXPECT_TRUE(sky(mask, 66, 10));    // past it
}

TEST(SkyMask, AWallWithoutReturnsIsSkyButAColouredOneIsNot) {
  // No return anywhere: a white wall as bright as the sky beside it (grey 175: no edge between
  // them) is taken for sky; a red one of that grey is not. The brighter white wall of the
  // drawn scene is not either: its edge against the sky is texture, which cuts it off the top.
  const cv::Mat none(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  cv::Mat image = drawnScene();
  EXPECT_FALSE(sky(SkyMask().compute(image, none), 160, 40));
  image(cv::Rect(140, 30, 40, 30)).setTo(cv::Scalar(175, 175, 175));
  EXPECT_TRUE(sky(SkyMask().compute(image, none), 160, 40));
  image(cv::Rect(140, 30, 40, 30)).setTo(cv::Scalar(140, 140, 255));
  EXPECT_FALSE(sky(SkyMask().compute(image, none), 160, 40));
  // Grey only: brightness, texture and the LiDAR decide.
  cv::Mat grey;
  cv::cvtColor(drawnScene(), grey, cv::COLOR_BGR2GRAY);
  const cv::Mat mask = SkyMask().compute(grey, drawnReturns());
  EXPECT_TRUE(sky(mask, 100, 5));
  EXPECT_FALSE(sky(mask, 40, 5));
  EXPECT_FALSE(sky(mask, 160, 40));
}

TEST(SkyMask, GivesEachColumnTheDepthOfItsHighestReturn) {
  // The crown's returns (8 m) reach row 26 over columns 20-59, the fence's (9 m) columns 80-119,
  // the wall's (12 m) columns 140-179; the road's (10 m) start at row 62. A column takes the
  // highest return within 8 columns of it.
  const std::vector<float> depth = SkyMask().topReturnDepth(drawnReturns());
  ASSERT_EQ(depth.size(), static_cast<std::size_t>(kWidth));
  EXPECT_EQ(depth[40], 8.f);
  EXPECT_EQ(depth[65], 8.f);  // within the window of the crown's last column
  EXPECT_EQ(depth[70], 10.f); // the road's only
  EXPECT_EQ(depth[100], 9.f);
  EXPECT_EQ(depth[160], 12.f);
  EXPECT_EQ(depth[185], 12.f);
  EXPECT_EQ(depth[195], 10.f);
  const cv::Mat none(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  EXPECT_EQ(SkyMask().topReturnDepth(none), std::vector<float>(kWidth, 0.f));
  // One ring passes a far wall (30 m, row 10) and a near one (12 m, a row lower): a column
  // between them takes the near wall's depth, not a lower ring's nearer return (5 m, row 20).
  cv::Mat ring = none.clone();
  ring(cv::Rect(100, 10, 5, 1)).setTo(30.f);
  ring(cv::Rect(106, 11, 5, 1)).setTo(12.f);
  ring(cv::Rect(100, 20, 11, 1)).setTo(5.f);
  const std::vector<float> ring_depth = SkyMask().topReturnDepth(ring);
  EXPECT_EQ(ring_depth[105], 12.f);
  EXPECT_EQ(ring_depth[92], 30.f); // only the far wall within its window
  EXPECT_THROW(SkyMask().topReturnDepth(cv::Mat(kHeight, kWidth, CV_8UC1)), InvalidInputError);
}

TEST(SkyMask, ItsSkyDepthBoundsEachRayByItsColumnOrNotAtAllInTheClearSky) {
  // Rows 0-1 of four columns are sky; column 0 has no return below it, columns 1-3 at 5, 5 and
  // 7 m; pixel (2, 0) is clear sky. Off the sky NaN; unbounded rays +inf.
  cv::Mat sky(3, 4, CV_8UC1, cv::Scalar(0));
  sky.rowRange(0, 2).setTo(255);
  cv::Mat clear(sky.size(), CV_8UC1, cv::Scalar(0));
  clear.at<std::uint8_t>(0, 2) = 255;
  const std::vector<float> column_depth{0.f, 5.f, 5.f, 7.f};
  const float inf = std::numeric_limits<float>::infinity();
  const cv::Mat depth = skyDepthImage(sky, column_depth, clear);
  ASSERT_EQ(depth.type(), CV_32FC1);
  ASSERT_EQ(depth.size(), sky.size());
  const std::vector<std::vector<float>> expected{{inf, 5.f, inf, 7.f}, {inf, 5.f, 5.f, 7.f}};
  for (int v = 0; v < 2; ++v)
    for (int u = 0; u < 4; ++u)
      EXPECT_EQ(depth.at<float>(v, u), expected[static_cast<std::size_t>(v)][static_cast<std::size_t>(u)])
          << u << "," << v;
  for (int u = 0; u < 4; ++u)
    EXPECT_TRUE(std::isnan(depth.at<float>(2, u))) << u;
  EXPECT_EQ(skyDepthImage(sky, column_depth).at<float>(0, 2), 5.f); // without a clear sky: the bound
  // What does not describe one image's sky is refused, named.
  EXPECT_EQ(test::errorOf([&] { skyDepthImage(cv::Mat(3, 4, CV_32FC1), column_depth); }),
            "sky depth: the sky mask must be CV_8UC1, not of type 5");
  EXPECT_EQ(test::errorOf([&] { skyDepthImage(sky, std::vector<float>(3)); }),
            "sky depth: the column depths must be one per image column (4), not 3");
  EXPECT_EQ(test::errorOf([&] { skyDepthImage(sky, column_depth, cv::Mat(4, 3, CV_8UC1)); }),
            "sky depth: the clear sky must be a CV_8UC1 mask of the sky's 4x3, not 3x4 of type 0");
}

TEST(SkyMask, AWallsDepthIsTheFartherSidesSoACrownBesideAColumnDoesNotStandForIt) {
  // The returns of GivesEachColumnTheDepthOfItsHighestReturn. On each side of a column, within
  // 8 columns and the column included, the nearest return on that side's highest ring; of the
  // two sides the farther.
  const SkyMask masker;
  const std::vector<float> depth = masker.wallDepth(drawnReturns());
  ASSERT_EQ(depth.size(), static_cast<std::size_t>(kWidth));
  EXPECT_EQ(depth[40], 8.f);
  EXPECT_EQ(depth[59], 8.f);  // the crown's last column: the crown on both sides
  EXPECT_EQ(depth[65], 10.f); // the crown on one side only: the road's on the other is farther
  EXPECT_EQ(masker.topReturnDepth(drawnReturns())[65], 8.f);
  EXPECT_EQ(depth[100], 9.f);
  EXPECT_EQ(depth[185], 12.f); // the wall on one side, the nearer road on the other
  const cv::Mat none(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  EXPECT_EQ(masker.wallDepth(none), std::vector<float>(kWidth, 0.f));
  // One ring passes a far wall (30 m, columns 100-104) and a near one (12 m, a row lower,
  // 106-110) above a lower ring's nearer returns (5 m): a column of the near wall takes its
  // depth, the column between the walls sees past both, one beside the far wall alone takes it.
  cv::Mat ring = none.clone();
  ring(cv::Rect(100, 10, 5, 1)).setTo(30.f);
  ring(cv::Rect(106, 11, 5, 1)).setTo(12.f);
  ring(cv::Rect(100, 20, 11, 1)).setTo(5.f);
  const std::vector<float> ring_depth = masker.wallDepth(ring);
  EXPECT_EQ(ring_depth[108], 12.f);
  EXPECT_EQ(ring_depth[105], 30.f);
  EXPECT_EQ(ring_depth[92], 30.f);
  EXPECT_THROW(masker.wallDepth(cv::Mat(kHeight, kWidth, CV_8UC1)), InvalidInputError);
}

TEST(SkyMask, ItsClearSkyIsClippedOrBlueNotGreyWhite) {
  // No return anywhere. The blue sky is clear; a grey-white wall as bright as it (grey 175) is
  // sky but not clear (a blank wall may look so); a clipped white patch at the top edge is.
  const cv::Mat none(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  cv::Mat image = drawnScene();
  image(cv::Rect(140, 30, 40, 30)).setTo(cv::Scalar(175, 175, 175));
  image(cv::Rect(140, 0, 40, 20)).setTo(cv::Scalar(252, 252, 252));
  const SkyMask masker;
  const cv::Mat mask = masker.compute(image, none);
  const cv::Mat clear = masker.clearSky(image, mask);
  ASSERT_EQ(clear.type(), CV_8UC1);
  ASSERT_TRUE(sky(mask, 160, 45));
  EXPECT_FALSE(sky(clear, 160, 45)); // grey-white
  EXPECT_TRUE(sky(clear, 100, 5));   // blue
  EXPECT_TRUE(sky(clear, 160, 8));   // clipped
  EXPECT_EQ(cv::countNonZero(clear & ~mask), 0);
  // Grey only: the clipped patch alone is clear.
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const cv::Mat grey_clear = masker.clearSky(grey, masker.compute(grey, none));
  EXPECT_TRUE(sky(grey_clear, 160, 8));
  EXPECT_FALSE(sky(grey_clear, 100, 5));
  // Nothing of a mask that is empty; a mask of another size is refused.
  EXPECT_EQ(cv::countNonZero(masker.clearSky(image, cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(0)))), 0);
  EXPECT_THROW(masker.clearSky(image, cv::Mat(kHeight - 1, kWidth, CV_8UC1, cv::Scalar(0))), InvalidInputError);
  EXPECT_THROW(masker.clearSky(cv::Mat(kHeight, kWidth, CV_32FC1), mask), InvalidInputError);
}

TEST(SkyMask, TheClippedOutlineIsTheClippedSkyBesideAnEdgeThatTheTextureKeptOut) {
  // A grey camera's clipped sky (255) over rows 0-39, a dark crown at columns 60-79 from the top
  // edge, a grey-white (200) strip of columns 120-129 across the sky, and a white clipped wall at
  // columns 150-169 from row 20 with its returns from row 24 down. The 5x5 texture keeps the
  // two columns beside each edge out of the mask; the outline holds the clipped ones within
  // the border (3) of it (beside the crown and beside the strip), not the strip's own edge
  // columns (grey-white, not clipped) nor the wall's pixels below its returns.
  cv::Mat grey(kHeight, kWidth, CV_8UC1, cv::Scalar(100));
  grey.rowRange(0, 40).setTo(255);
  grey(cv::Rect(60, 0, 20, 40)).setTo(30);
  grey(cv::Rect(120, 0, 10, 40)).setTo(200);
  cv::Mat returns(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  for (int v = 44; v < kHeight; v += 4)
    returns.row(v).setTo(10.f);
  for (int v = 24; v < 40; v += 4)
    returns(cv::Rect(150, v, 20, 1)).setTo(12.f);
  const SkyMask masker;
  const cv::Mat open = masker.computeWithoutBorder(grey, returns);
  ASSERT_TRUE(sky(open, 50, 10));
  ASSERT_FALSE(sky(open, 58, 10)); // the crown within the texture window
  const cv::Mat outline = masker.clippedOutline(grey, returns, open);
  ASSERT_EQ(outline.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(outline & open), 0);
  for (int u : {58, 59, 80, 81, 118, 119, 130, 131})
    EXPECT_TRUE(sky(outline, u, 10)) << "column " << u;
  for (int u : {57, 60, 79, 82, 120, 121, 125, 128, 129})
    EXPECT_FALSE(sky(outline, u, 10)) << "column " << u;
  EXPECT_FALSE(sky(outline, 160, 25)); // the clipped wall below its highest returns (row 24)
  // Without a border nothing is reached; a mask or returns of another size are refused.
  SkyMask no_border;
  no_border.setBorder(0);
  EXPECT_EQ(cv::countNonZero(no_border.clippedOutline(grey, returns, open)), 0);
  EXPECT_THROW(masker.clippedOutline(grey, returns, open.rowRange(1, kHeight)), InvalidInputError);
  EXPECT_THROW(masker.clippedOutline(grey, returns.colRange(1, kWidth), open), InvalidInputError);
}

TEST(SkyMask, RefusesImagesOfAnotherTypeOrSize) {
  const cv::Mat returns = drawnReturns();
  EXPECT_THROW(SkyMask().compute(cv::Mat(kHeight, kWidth, CV_32FC3), returns), InvalidInputError);
  EXPECT_THROW(SkyMask().compute(drawnScene(), cv::Mat(kHeight, kWidth - 1, CV_32FC1)), InvalidInputError);
  SkyMask mask;
  mask.setBorder(-1);
  EXPECT_THROW(mask.compute(drawnScene(), returns), ConfigError);
}

TEST(OpenSkyCoverage, CountsTheSkyPixelsASheetCovers) {
  // The sky: the top 40 rows. A sheet at 10 m over world y in [-5, -3] (rows 0-19 at f 100)
  // covers half of them; at the next frame's pose, 1 m lower (y down), rows 0-9: a quarter.
  cv::Mat mask(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  mask.rowRange(0, 40).setTo(255);
  OpenSkyCoverage coverage(camera());
  coverage.addMask(0, mask);
  coverage.setPose(0, Eigen::Isometry3d::Identity());
  Eigen::Isometry3d lowered = Eigen::Isometry3d::Identity();
  lowered.translation().y() = 1.0;
  coverage.setPose(1, lowered); // the pose first, the mask after
  coverage.addMask(1, mask);
  const SkyCoverage c = coverage.scoreMesh(square(-20.f, 20.f, -5.f, -3.f, 10.f));
  EXPECT_EQ(c.frames, 2u);
  EXPECT_EQ(c.sky_pixels, 2u * 40 * kWidth);
  EXPECT_EQ(c.covered_pixels, 20u * kWidth + 10u * kWidth);
  EXPECT_NEAR(c.share, 30.0 / 80.0, 1e-12);
  EXPECT_NEAR(c.mean_frame_share, (0.5 + 0.25) / 2, 1e-12);
  EXPECT_NEAR(c.worst_share, 0.5, 1e-12);
  EXPECT_EQ(c.worst_frame, 0u);
  // Filters on the covering point, all from one render a frame: only x > 0 (the right half of
  // each frame's cover), and none; each as when scored alone.
  const TriangleMesh sheet = square(-20.f, 20.f, -5.f, -3.f, 10.f);
  const OpenSkyCoverage::SurfaceFilter right = [](const Eigen::Vector3f& p) { return p.x() > 0.f; };
  const OpenSkyCoverage::SurfaceFilter nothing = [](const Eigen::Vector3f&) { return false; };
  std::vector<OpenSkyCoverage::Tally> tallies(3);
  MeshViewScoring views;
  coverage.addViews(views, tallies[0], right);
  coverage.addViews(views, tallies[1]);
  coverage.addViews(views, tallies[2], nothing);
  EXPECT_EQ(views.score(sheet), 2u) << "one rendering a frame";
  const std::vector<SkyCoverage> filtered = {tallies[0].coverage(), tallies[1].coverage(), tallies[2].coverage()};
  const SkyCoverage alone = coverage.scoreMesh(sheet, right);
  EXPECT_NEAR(static_cast<double>(alone.covered_pixels), 15.0 * kWidth, 2.0 * 30) << "the right half, within a pixel a row";
  for (const SkyCoverage& f : {filtered[0], alone}) {
    EXPECT_EQ(f.covered_pixels, alone.covered_pixels);
    EXPECT_EQ(f.frame_share, alone.frame_share);
    EXPECT_EQ(f.covered_depth_median_m, alone.covered_depth_median_m);
  }
  EXPECT_EQ(filtered[1].covered_pixels, c.covered_pixels);
  EXPECT_EQ(filtered[1].frame_share, c.frame_share);
  EXPECT_EQ(filtered[2].covered_pixels, 0u);
  EXPECT_EQ(filtered[2].frames, 2u);
  EXPECT_EQ(filtered[2].sky_pixels, c.sky_pixels);
  // A mesh below the sky covers none of it.
  EXPECT_EQ(coverage.scoreMesh(square(-20.f, 20.f, 1.f, 4.f, 10.f)).covered_pixels, 0u);
  EXPECT_THROW(coverage.addMask(0, mask), InvalidInputError);
  EXPECT_THROW(coverage.addMask(2, cv::Mat(kHeight, kWidth, CV_8UC3)), InvalidInputError);
}

TEST(OpenSkyCoverage, DrawsTheSkyCyanAndItsCoveredPixelsRed) {
  cv::Mat mask(kHeight, kWidth, CV_8UC1, cv::Scalar(0)), rendered(kHeight, kWidth, CV_32FC1, cv::Scalar(0));
  mask.rowRange(0, 40).setTo(255);
  rendered.rowRange(0, 20).setTo(10.f);
  const cv::Mat picture =
      OpenSkyCoverage::drawCoverage(cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(100)), mask, rendered);
  EXPECT_EQ(picture.at<cv::Vec3b>(10, 5), cv::Vec3b(50, 50, 177));  // covered sky: red
  EXPECT_EQ(picture.at<cv::Vec3b>(30, 5), cv::Vec3b(177, 177, 50)); // open sky: cyan
  EXPECT_EQ(picture.at<cv::Vec3b>(60, 5), cv::Vec3b(100, 100, 100)); // no sky: the image
}
