// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Evaluation protocol 6 on real frames: the sky mask of a hand-checked KITTI frame, and the
// sheets over the road in front of the open sky that sky carving clears, and the clear sky that
// gives no depth.
#include <msf/common/exceptions.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/fused_cloud.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/pipeline/sky_scoring.h>

#include <test_support.h>

#include <gtest/gtest.h>
#include <pcl/conversions.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <set>

namespace {

std::string drive() { return msf::test::kittiDir() + "/odometry/sequences/04_10_50"; }

} // namespace

TEST(OpenSky, TheMaskOfAHandCheckedKittiFrame) {
  MSF_REQUIRE_KITTI();
  // Frame 000020 of 04_10_50: open sky over the road between a birch (left) and a row of
  // trees (right), a house with a red roof on the left, the van ahead.
  const msf::Sequence sequence(drive());
  const msf::Frame frame = sequence.load(20);
  msf::SkyScoring sky(sequence.calibration(), msf::ProjectionConfig(), {});
  const cv::Mat mask = sky.maskOf(frame);
  const auto at = [&](int u, int v) { return mask.at<std::uint8_t>(v, u) != 0; };
  EXPECT_TRUE(at(520, 20));   // top centre: blue sky
  EXPECT_TRUE(at(470, 60));   // the sky right of the birch
  EXPECT_TRUE(at(150, 10));   // the sky over the house
  EXPECT_FALSE(at(330, 60));  // the birch's crown
  EXPECT_FALSE(at(900, 60));  // the crowns of the row of trees
  EXPECT_FALSE(at(120, 50));  // the red roof
  EXPECT_FALSE(at(600, 190)); // the van
  EXPECT_FALSE(at(500, 300)); // the road
  const double share = cv::countNonZero(mask) / static_cast<double>(mask.total());
  EXPECT_GT(share, 0.05);
  EXPECT_LT(share, 0.15);
}

TEST(OpenSky, SkyCarvingClearsTheSheetsOverTheRoadInFrontOfTheSky) {
  // Frames 20-35 of 04_10_50: without sky carving the map hangs surfaces a few metres in front
  // of the open sky of frame 35, over the road (the van's ghost: the interpolated LiDAR of
  // frames 20-22, which every later ray through it sees past into the sky); carving along the
  // sky's rays (tsdf_integrator.sky_carving) clears them.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(drive());
  std::map<bool, msf::SkyCoverage> covered;
  for (const bool sky_carving : {false, true}) {
    msf::PipelineConfig config;
    config.integrator.sky_carving = sky_carving;
    // Far carving and the scan (in view where the frame has no depth) clear part of the same
    // ghost: sky carving alone here.
    config.integrator.far_carving = false;
    config.integrator.scan_carving_m = 0.0;
    msf::Reconstructor engine(sequence.calibration(), config);
    msf::SkyScoring sky(sequence.calibration(), config.projection, {});
    for (std::size_t i = 20; i <= 35; ++i) {
      const msf::Frame frame = sequence.load(i);
      sky.addFrame(frame);
      sky.setPose(i, engine.addFrame(frame).T_world_cam0);
    }
    covered[sky_carving] = sky.score({{"mesh", &engine.mesh()}}).at("mesh");
    std::printf("  sky carving %d: %.4f of the sky covered, worst %.4f at frame %zu\n", sky_carving,
                covered[sky_carving].share, covered[sky_carving].worst_share, covered[sky_carving].worst_frame);
  }
  const msf::SkyCoverage& without = covered[false];
  EXPECT_EQ(without.frames, 16u);
  EXPECT_GT(without.sky_pixels, 16u * 20000);
  EXPECT_GT(without.share, 0.01);
  EXPECT_EQ(without.worst_frame, 35u);
  EXPECT_GT(without.worst_share, 0.15);
  EXPECT_LT(without.covered_depth_median_m, 10.0); // near the camera, over the road
  const msf::SkyCoverage& with = covered[true];
  EXPECT_EQ(with.sky_pixels, without.sky_pixels);
  // The whole drive (41 frames, msf_reconstruct): 11.47 -> 0.22 %, worst 36.45 -> 3.18 %.
  EXPECT_LT(with.share, without.share / 10);
  EXPECT_LT(with.worst_share, without.worst_share / 5);
}

TEST(OpenSky, AClearSkyGivesNoDepth) {
  // Frame 2 of raw drive 0009: SGBM smears the crowns' disparity over the overexposed sky
  // between them, thousands of pixels of depth 15-25 m, which hung in the map as sheets. With
  // fusion.clear_sky the fused frame has no depth in the clear sky, and is the same everywhere
  // else but at camera 0's clipped pixels beside the crowns; the open sky that sky carving takes
  // is the one the fusion found, with the pixels it withheld.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(msf::test::kittiDir() + "/raw/2011_09_26/2011_09_26_drive_0009_sync");
  const msf::Frame frame = sequence.load(2);
  ASSERT_FALSE(frame.color.empty());
  msf::PipelineConfig config;
  config.fusion.clear_sky = false;
  const msf::FrameResult without = msf::Reconstructor(sequence.calibration(), config).computeDepth(frame);
  config.fusion.clear_sky = true;
  const msf::FrameResult with = msf::Reconstructor(sequence.calibration(), config).computeDepth(frame);
  ASSERT_FALSE(with.sky.empty());
  const cv::Mat clear = msf::SkyMask().clearSky(frame.color, with.sky);
  const cv::Mat clear_in_either = clear | msf::SkyMask().clearSky(frame.left, with.sky);
  EXPECT_EQ(cv::countNonZero(without.sky & ~with.sky), 0);
  EXPECT_EQ(cv::countNonZero(with.sky & ~without.sky & ~clear_in_either), 0);
  EXPECT_GT(cv::countNonZero(with.sky & ~without.sky & ~clear), 100); // camera 0's clipped outline
  EXPECT_GT(cv::countNonZero(with.sky & ~without.sky), 100); // withheld beside the crowns, within the border
  const cv::Mat had = without.fused.depth > 0.f, has = with.fused.depth > 0.f;
  EXPECT_GT(cv::countNonZero(clear), 15000);
  EXPECT_GT(cv::countNonZero(had & clear), 3000);
  EXPECT_EQ(cv::countNonZero(has & clear), 0);
  EXPECT_GT(cv::countNonZero((with.stereo_depth > 0.f) & clear), 3000); // the stages' own images are kept
  // The clear sky that the map carves past the returns (sky_depth +inf where it was bounded
  // without clear_sky): only with clear_sky, and only in the clear sky.
  const float inf = std::numeric_limits<float>::infinity();
  const cv::Mat carved_past = (with.sky_depth == inf) & (without.sky_depth != inf) & without.sky;
  EXPECT_GT(cv::countNonZero(carved_past), 10000);
  EXPECT_EQ(cv::countNonZero(carved_past & ~clear), 0);
  cv::Mat differs;
  cv::compare(without.fused.depth, with.fused.depth, differs, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs & ~clear_in_either), 0);
  cv::compare(without.fused.weight, with.fused.weight, differs, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs & ~clear_in_either), 0);
}

TEST(OpenSky, TheHoleFillKeepsOutOfTheSkyHoweverTheMapCarves) {
  // The frame's depth is the fusion's, whatever the map does with it: with sky carving off the
  // open sky is still found, and the small-hole fill (fusion.hole_fill_px) still leaves it empty.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(drive());
  const msf::Frame frame = sequence.load(20);
  msf::PipelineConfig config;
  msf::Reconstructor carving(sequence.calibration(), config);
  config.integrator.sky_carving = false;
  msf::Reconstructor not_carving(sequence.calibration(), config);
  const msf::FrameResult with = carving.addFrame(frame), without = not_carving.addFrame(frame);
  ASSERT_GT(cv::countNonZero(with.sky), 20000);
  ASSERT_EQ(without.sky.size(), with.sky.size()) << "no open sky found without sky carving";
  EXPECT_EQ(cv::norm(with.sky, without.sky, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero((without.fused.depth > 0.f) & without.sky), 0) << "a hole filled in the open sky";
  const cv::Mat had = with.fused.depth > 0.f, has = without.fused.depth > 0.f;
  EXPECT_EQ(cv::countNonZero(had != has), 0);
  EXPECT_EQ(cv::countNonZero((with.fused.depth != without.fused.depth) & had), 0);
}

TEST(OpenSky, AFusedCloudCarriesTheFramesOpenSky) {
  // What msf_fuse writes (field sky_depth) and msf_integrate and msfusion read back: the
  // frame's open sky (NaN elsewhere), bounded in each column by the depth of its highest LiDAR
  // return, +inf in the clear sky, whose rays nothing bounds, as sky carving takes it.
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(drive());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig());
  const msf::FrameResult r = engine.computeDepth(sequence.load(20));
  ASSERT_GT(cv::countNonZero(r.sky), 20000);
  pcl::PCLPointCloud2 blob;
  pcl::toPCLPointCloud2(msf::fusedCloud(r, sequence.calibration()), blob);
  const cv::Mat sky_depth = msf::readSkyDepth(blob, "fused");
  ASSERT_EQ(sky_depth.size(), r.sky_depth.size());
  for (int v = 0; v < sky_depth.rows; ++v)
    ASSERT_EQ(std::memcmp(sky_depth.ptr(v), r.sky_depth.ptr(v), sky_depth.cols * sizeof(float)), 0) << v;
  const cv::Mat is_sky = sky_depth == sky_depth; // not NaN
  EXPECT_EQ(cv::countNonZero(is_sky != r.sky), 0);
  EXPECT_GT(cv::countNonZero(sky_depth == std::numeric_limits<float>::infinity()), 10000); // a blue sky
  std::size_t bounded = 0;
  for (int u = 0; u < sky_depth.cols; ++u) {
    std::set<float> bounds; // one per column: its highest return's depth
    for (int v = 0; v < sky_depth.rows; ++v) {
      const float d = sky_depth.at<float>(v, u);
      if (std::isfinite(d))
        bounds.insert(d);
    }
    EXPECT_LE(bounds.size(), 1u) << u;
    EXPECT_TRUE(bounds.empty() || *bounds.begin() > 0.f) << u;
    bounded += !bounds.empty();
  }
  EXPECT_GT(bounded, 100u); // most of the grey-white sky's columns have a return below it
  // A cloud without the field carries no sky; a field of another type is refused, named.
  pcl::toPCLPointCloud2(pcl::PointCloud<pcl::PointXYZ>(4, 3), blob);
  EXPECT_TRUE(msf::readSkyDepth(blob, "plain").empty());
  blob.fields.push_back(pcl::PCLPointField());
  blob.fields.back().name = "sky_depth";
  blob.fields.back().datatype = pcl::PCLPointField::FLOAT64;
  blob.fields.back().count = 1;
  EXPECT_THROW(
      {
        try {
          msf::readSkyDepth(blob, "cloud 'x.pcd'");
        } catch (const msf::InvalidInputError& e) {
          EXPECT_STREQ(e.what(), "cloud 'x.pcd': field 'sky_depth' must be one float32");
          throw;
        }
      },
      msf::InvalidInputError);
}
