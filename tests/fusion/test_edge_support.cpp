// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// supportAtDepthEdges: a fused disparity between the two surfaces of a depth edge takes the
// nearest real return's; elsewhere nothing changes.
#include <msf/common/exceptions.h>
#include <msf/fusion/edge_support.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

constexpr float kFB = 380.f; // disparity = 380 / z: 10 m -> 38 px, 40 m -> 9.5 px

/// Returns on rings 5 rows apart: a foreground (10 m) over the rows < 10 of columns < 20, the
/// background (40 m) elsewhere; the fused depth is `fill` everywhere.
struct Scene {
  cv::Mat lidar{30, 40, CV_32FC1, cv::Scalar(0)}, distance{30, 40, CV_32FC1, cv::Scalar(3)};
  cv::Mat fused;
  explicit Scene(float fill) : fused(30, 40, CV_32FC1, cv::Scalar(fill)) {
    for (int v = 0; v < lidar.rows; v += 5)
      for (int u = 0; u < lidar.cols; ++u) {
        lidar.at<float>(v, u) = v < 10 && u < 20 ? 10.f : 40.f;
        distance.at<float>(v, u) = 0.f;
      }
  }
  cv::Mat run(const msf::DepthFusionConfig& config = {}) {
    msf::EdgeSupportBuffers buffers;
    cv::Mat out = fused.clone();
    msf::supportAtDepthEdges(lidar, distance, kFB, config, out, buffers);
    return out;
  }
};

TEST(EdgeSupport, ABlendBetweenTwoSurfacesTakesTheNearerSurface) {
  Scene scene(15.f); // 25.3 px: 12.7 from the foreground, 15.8 from the background
  const cv::Mat out = scene.run();
  EXPECT_FLOAT_EQ(out.at<float>(7, 5), 10.f);   // returns of both surfaces within 6 rows
  EXPECT_FLOAT_EQ(out.at<float>(7, 22), 10.f);  // and within 3 columns of the foreground's side
  EXPECT_FLOAT_EQ(out.at<float>(25, 5), 15.f);  // only background returns around: no edge
  EXPECT_FLOAT_EQ(out.at<float>(7, 30), 15.f);  // the foreground is 10 columns away
  Scene far(30.f); // 12.7 px: nearer the background's 9.5
  EXPECT_FLOAT_EQ(far.run().at<float>(7, 5), 40.f);
}

TEST(EdgeSupport, ValuesOnASurfaceOrWithoutReturnsAreKept) {
  Scene near_background(37.f); // 10.3 px: within 2 px of the background's 9.5
  EXPECT_FLOAT_EQ(near_background.run().at<float>(7, 5), 37.f);
  Scene scene(15.f);
  scene.fused.at<float>(7, 6) = 0.f; // no fused depth stays none
  scene.distance.setTo(1.f);         // interpolated values are not returns
  const cv::Mat out = scene.run();
  EXPECT_FLOAT_EQ(out.at<float>(7, 5), 15.f);
  EXPECT_FLOAT_EQ(out.at<float>(7, 6), 0.f);
  // Without a distance image every LiDAR depth counts as a return.
  msf::EdgeSupportBuffers buffers;
  cv::Mat fused = scene.fused.clone();
  msf::supportAtDepthEdges(scene.lidar, cv::Mat(), kFB, {}, fused, buffers);
  EXPECT_FLOAT_EQ(fused.at<float>(7, 5), 10.f);
}

TEST(EdgeSupport, ValuesNearerOrFartherThanBothSurfacesAreKept) {
  // A pole the LiDAR missed (5 m: 76 px, nearer than every return in the window) is not
  // between the two surfaces: it keeps its depth, as does a value beyond the background.
  EXPECT_FLOAT_EQ(Scene(5.f).run().at<float>(7, 5), 5.f);
  EXPECT_FLOAT_EQ(Scene(80.f).run().at<float>(7, 5), 80.f); // 4.75 px, beyond 40 m's 9.5
}

TEST(EdgeSupport, TheJumpAndTheWindowBoundWhatIsAnEdge) {
  msf::DepthFusionConfig config;
  config.edge_jump_px = 30.f; // 38 - 9.5 = 28.5 px is no edge now
  EXPECT_FLOAT_EQ(Scene(15.f).run(config).at<float>(7, 5), 15.f);
  config = {};
  config.edge_window_rows = 3; // rows 6..8 hold no return
  EXPECT_FLOAT_EQ(Scene(15.f).run(config).at<float>(7, 5), 15.f);
  config.edge_window_rows = 11; // rows 2..12: returns at rows 5 (10 m) and 10 (40 m)
  EXPECT_FLOAT_EQ(Scene(15.f).run(config).at<float>(7, 5), 10.f);
  config.edge_tolerance_px = 13.f; // 12.7 px from the foreground is on it now
  EXPECT_FLOAT_EQ(Scene(15.f).run(config).at<float>(7, 5), 15.f);
}

TEST(EdgeSupport, ConfigRejectsEvenWindowsAndNonPositiveJumps) {
  const auto invalid = [](auto change) {
    msf::DepthFusionConfig config;
    change(config);
    EXPECT_THROW(config.validate(), msf::ConfigError);
  };
  invalid([](msf::DepthFusionConfig& c) { c.edge_window_rows = 12; });
  invalid([](msf::DepthFusionConfig& c) { c.edge_window_cols = 0; });
  invalid([](msf::DepthFusionConfig& c) { c.edge_jump_px = 0.f; });
  invalid([](msf::DepthFusionConfig& c) { c.edge_tolerance_px = -1.f; });
  msf::DepthFusionConfig config;
  config.edge_window_rows = 12;
  try {
    config.validate();
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("fusion.edge_window_rows"), std::string::npos) << e.what();
  }
}

} // namespace
