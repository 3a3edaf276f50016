// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/fusion/clear_sky.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/fusion_model.h>
#include <msf/fusion/point_types.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace {

using Fusion = msf::DepthFusion<>;
using LidarCloud = pcl::PointCloud<msf::PointXYZID>;
using StereoCloud = pcl::PointCloud<msf::PointXYZRGBConfidence>;
using FusedCloud = pcl::PointCloud<msf::PointXYZRGBWeight>;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kFocal = 500.0, kBaseline = 0.5, kFB = kFocal * kBaseline;

msf::Calibration calibration(int width, int height) {
  msf::Calibration c;
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  P(0, 0) = P(1, 1) = kFocal;
  P(0, 2) = width / 2.0;
  P(1, 2) = height / 2.0;
  P(2, 2) = 1.0;
  for (auto& p : c.P)
    p = P;
  c.P[1](0, 3) = -kFB;
  c.image_size = cv::Size(width, height);
  c.T_cam0_velo.translation() = Eigen::Vector3d(0.0, -0.08, -0.3); // LiDAR 8 cm above camera 0
  c.source = "synthetic";
  return c;
}

/// A point on the ray of pixel (u, v) at depth z (NaN when z <= 0).
template <typename PointT>
PointT onRay(int u, int v, float z, int width, int height) {
  PointT p;
  if (z > 0.f) {
    p.x = (u - width / 2.f) * z / static_cast<float>(kFocal);
    p.y = (v - height / 2.f) * z / static_cast<float>(kFocal);
    p.z = z;
  } else {
    p.x = p.y = p.z = kNaN;
  }
  return p;
}

/// Clouds of w x h from per-pixel depths (0 = none), LiDAR distances and stereo confidences.
struct Inputs {
  LidarCloud::Ptr lidar{new LidarCloud};
  StereoCloud::Ptr stereo{new StereoCloud};
  Inputs(int w, int h) {
    lidar->resize(static_cast<std::size_t>(w) * h);
    lidar->width = w;
    lidar->height = h;
    stereo->resize(static_cast<std::size_t>(w) * h);
    stereo->width = w;
    stereo->height = h;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        setLidar(u, v, 0.f, 0.f);
        setStereo(u, v, 0.f, 0.f);
      }
  }
  void setLidar(int u, int v, float z, float distance) {
    auto p = onRay<msf::PointXYZID>(u, v, z, lidar->width, lidar->height);
    p.distance = distance;
    lidar->at(u, v) = p;
  }
  void setStereo(int u, int v, float z, float confidence) {
    auto p = onRay<msf::PointXYZRGBConfidence>(u, v, z, stereo->width, stereo->height);
    p.confidence = z > 0.f ? confidence : 0.f;
    p.r = 10;
    p.g = 20;
    p.b = 30;
    stereo->at(u, v) = p;
  }
};

FusedCloud fuse(const Inputs& in, const msf::DepthFusionConfig& config) {
  Fusion fusion(config);
  fusion.setCalibration(calibration(static_cast<int>(in.stereo->width), static_cast<int>(in.stereo->height)));
  fusion.setInputLidar(in.lidar);
  fusion.setInputStereo(in.stereo);
  FusedCloud out;
  fusion.fuse(out);
  return out;
}

// ---- eq. 6 on hand-made pixels --------------------------------------------------------------

TEST(DepthFusionPaper, Eq6OnHandMadePixels) {
  msf::DepthFusionConfig config;
  config.method = msf::FusionMethod::Paper;
  config.paper_lidar_gain = 1.f;
  config.paper_lidar_distance_px = 4.f;
  config.paper_stereo_reference_depth_m = 10.f;
  config.edge_support = false; // eq. 6 alone: the returns at 10 and 20 m make an edge (test_edge_support)
  Inputs in(5, 2);
  in.setLidar(0, 0, 0.f, 0.f);  in.setStereo(0, 0, 12.f, 0.8f);  // invalid LiDAR: stereo value
  in.setLidar(1, 0, 10.f, 0.f); in.setStereo(1, 0, 0.f, 0.f);    // invalid stereo: LiDAR value
  in.setLidar(2, 0, 0.f, 0.f);  in.setStereo(2, 0, 0.f, 0.f);    // neither: NaN
  in.setLidar(3, 0, 10.f, 4.f); in.setStereo(3, 0, 8.f, 0.5f);   // both valid, near
  in.setLidar(4, 0, 20.f, 0.f); in.setStereo(4, 0, 22.f, 1.0f);  // both valid, far
  const FusedCloud out = fuse(in, config);

  EXPECT_FLOAT_EQ(out.at(0, 0).z, 12.f);
  EXPECT_FLOAT_EQ(out.at(1, 0).z, 10.f);
  EXPECT_TRUE(std::isnan(out.at(2, 0).z));
  EXPECT_EQ(out.at(2, 0).weight, 0.f);
  // Pixel 3: w_L = 1 / (1 + 4/4) = 0.5, w_S = 0.5 * min(1, (10/8)^2) = 0.5: w2 = 1, w1 = 1:
  // y = (8 * 1 + 10 * 1 * 1) / (1 + 1 * 1) = 9, between the two.
  EXPECT_NEAR(out.at(3, 0).z, 9.f, 1e-5f);
  // Its weight, min(1, w_L + w_S) = 1, in the integrator's unit: the inverse variance of the
  // best stereo match at 9 m.
  const float sigma_best = 9.f * 9.f * config.stereo_sigma_min_px / static_cast<float>(kFB);
  EXPECT_NEAR(out.at(3, 0).weight, 1.f / (sigma_best * sigma_best), 1e-3f * out.at(3, 0).weight);
  // Pixel 4: w_L = 1, w_S = 1 * (10/22)^2 = 0.2066: w2 = 4.84: y = (22 + 20 w2) / (1 + w2).
  const float w2 = 1.f / (100.f / (22.f * 22.f));
  EXPECT_NEAR(out.at(4, 0).z, (22.f + 20.f * w2) / (1.f + w2), 1e-4f);
  EXPECT_GT(out.at(4, 0).z, 20.f);
  EXPECT_LT(out.at(4, 0).z, 22.f);
  // Fused points stay on their pixel's ray.
  const auto ray = onRay<pcl::PointXYZ>(3, 0, 9.f, 5, 2);
  EXPECT_NEAR(out.at(3, 0).x, ray.x, 1e-5f);
  EXPECT_NEAR(out.at(3, 0).y, ray.y, 1e-5f);
}

TEST(DepthFusionPaper, PixelFunctionIsTheWeightedMean) {
  msf::DepthFusionConfig config;
  config.paper_lidar_gain = 1.f;
  config.paper_lidar_distance_px = 4.f;
  config.paper_stereo_reference_depth_m = 10.f;
  msf::FusionInputs in;
  in.z_lidar = 30.f;
  in.lidar_distance = 2.f;
  in.z_stereo = 25.f;
  in.stereo_confidence = 0.3f;
  const float w_L = 1.f / (1.f + 2.f / 4.f), w_S = 0.3f * (10.f / 25.f) * (10.f / 25.f);
  EXPECT_NEAR(msf::fusePaper(in, config).z, (w_S * 25.f + w_L * 30.f) / (w_S + w_L), 1e-4f);
  // The stereo confidence has a floor, so a zero-confidence match still counts a little.
  in.stereo_confidence = 0.f;
  const float w_S0 = config.paper_min_stereo_confidence * 0.16f;
  EXPECT_NEAR(msf::fusePaper(in, config).z, (w_S0 * 25.f + w_L * 30.f) / (w_S0 + w_L), 1e-4f);
}

TEST(DepthFusionPaper, AsWrittenTheStereoWeightCancels) {
  // Eq. 6 with w1 = w_S and w2 = w_L: y = (y1 + w_L y2) / (1 + w_L) whatever stereo's confidence.
  msf::DepthFusionConfig config;
  config.paper_weights = msf::PaperWeights::AsWritten;
  config.paper_lidar_gain = 1.f;
  config.paper_lidar_distance_px = 4.f;
  msf::FusionInputs in;
  in.z_lidar = 30.f;
  in.lidar_distance = 4.f; // w_L = 0.5
  in.z_stereo = 24.f;
  for (const float confidence : {0.f, 0.3f, 1.f}) {
    in.stereo_confidence = confidence;
    EXPECT_NEAR(msf::fusePaper(in, config).z, (24.f + 0.5f * 30.f) / 1.5f, 1e-4f) << confidence;
  }
  // Without LiDAR (w1 = 1, w2 = 0) stereo is used; without stereo (w1 = 0) the LiDAR.
  msf::FusionInputs stereo_only = in, lidar_only = in;
  stereo_only.z_lidar = 0.f;
  lidar_only.z_stereo = 0.f;
  EXPECT_FLOAT_EQ(msf::fusePaper(stereo_only, config).z, 24.f);
  EXPECT_FLOAT_EQ(msf::fusePaper(lidar_only, config).z, 30.f);
  // The project's reading weighs stereo by its confidence: a confident match pulls harder.
  config.paper_weights = msf::PaperWeights::Relative;
  in.stereo_confidence = 1.f;
  const float confident = msf::fusePaper(in, config).z;
  in.stereo_confidence = 0.1f;
  EXPECT_LT(confident, msf::fusePaper(in, config).z);
}

TEST(DepthFusionPaper, PaperWeightsKeyIsNamedWhenWrong) {
  msf::DepthFusionConfig config;
  try {
    msf::ConfigFile::fromText("fusion:\n  paper_weights: literal\n", "c.yaml").read(config);
    ADD_FAILURE() << "paper_weights: literal was accepted";
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("fusion.paper_weights"), std::string::npos) << e.what();
  }
  msf::ConfigFile::fromText("fusion:\n  paper_weights: as_written\n", "c.yaml").read(config);
  EXPECT_EQ(config.paper_weights, msf::PaperWeights::AsWritten);
}

// ---- uncertainty ---------------------------------------------------------------------------

/// sigma_S = 0.3 + 3.7 (1 - c)^2 px, sigma_L = 0.3 + 0.05 distance + 0.7 range px.
msf::DepthFusionConfig handMadeSigmas() {
  msf::DepthFusionConfig config;
  config.stereo_sigma_min_px = 0.3f;
  config.stereo_sigma_max_px = 4.f;
  config.lidar_sigma_px = 0.3f;
  config.lidar_sigma_per_distance = 0.05f;
  config.lidar_sigma_per_range = 0.7f;
  config.disagreement_k_sigma = 3.f;
  return config;
}

TEST(DepthFusionUncertainty, InverseVarianceMeanInDisparity) {
  const msf::DepthFusionConfig config = handMadeSigmas();
  msf::FusionInputs in;
  in.z_lidar = static_cast<float>(kFB / 20.0);  // disparity 20
  in.lidar_distance = 6.f;                        // sigma_L = 0.3 + 0.3 = 0.6
  in.z_stereo = static_cast<float>(kFB / 21.0); // disparity 21, within 3 sigma
  in.stereo_confidence = 1.f;                     // sigma_S = 0.3
  const float vL = 0.36f, vS = 0.09f;
  const float d = (20.f * vS + 21.f * vL) / (vL + vS); // 20.8
  const auto f = msf::fuseUncertainty(in, config, static_cast<float>(kFB));
  EXPECT_NEAR(f.z, kFB / d, 1e-4);
  // The weight is the inverse variance of the fused depth: the sum of the two sources' (the
  // LiDAR's range noise and interpolation error, 0.05 px a pixel of distance, in depth; the
  // stereo's 0.3 px in depth), and the two samples' spread about the mean, each weighted.
  // The free space in front weighs the sum alone.
  const float fb = static_cast<float>(kFB), z_L = in.z_lidar, z_S = in.z_stereo;
  const float interpolation = z_L * z_L * 0.05f * 6.f / fb, range = config.lidar_range_sigma_m;
  const float sigma_S = z_S * z_S * 0.3f / fb;
  const float w_L = 1.f / (range * range + interpolation * interpolation), w_S = 1.f / (sigma_S * sigma_S);
  const float z = f.z, spread = (w_L * (z_L - z) * (z_L - z) + w_S * (z_S - z) * (z_S - z)) / (w_L + w_S);
  EXPECT_NEAR(f.free_weight, w_L + w_S, 1e-3f * f.free_weight);
  EXPECT_NEAR(f.weight, 1.f / (1.f / (w_L + w_S) + spread), 1e-3f * f.weight);
  EXPECT_LT(f.weight, 0.5f * f.free_weight); // 0.6 m apart at 20 m: the mean is not a LiDAR return
  // Far apart (4 px > 3 * sqrt(0.45)): not averaged, the more certain (stereo) wins.
  in.z_stereo = static_cast<float>(kFB / 24.0);
  EXPECT_FLOAT_EQ(msf::fuseUncertainty(in, config, static_cast<float>(kFB)).z, in.z_stereo);
  // A weak stereo match (sigma_S = 0.3 + 3.7 * 0.8^2 = 2.668 px) is within 3 sigma: the mean
  // leans to the LiDAR.
  in.stereo_confidence = 0.2f;
  const float vS2 = 2.668f * 2.668f;
  EXPECT_NEAR(msf::fuseUncertainty(in, config, static_cast<float>(kFB)).z, kFB / ((20.f * vS2 + 24.f * vL) / (vL + vS2)),
              1e-3);
  // Far apart and the LiDAR more certain: the LiDAR alone.
  in.stereo_confidence = 0.6f; // sigma_S = 0.3 + 3.7 * 0.16 = 0.892 px
  in.z_stereo = static_cast<float>(kFB / 26.0);
  EXPECT_FLOAT_EQ(msf::fuseUncertainty(in, config, static_cast<float>(kFB)).z, in.z_lidar);
  // Stereo sigma model: min at confidence 1, max at 0, quadratic between.
  EXPECT_FLOAT_EQ(msf::stereoSigmaPx(1.f, config), 0.3f);
  EXPECT_FLOAT_EQ(msf::stereoSigmaPx(0.f, config), 4.f);
  EXPECT_NEAR(msf::stereoSigmaPx(0.5f, config), 0.3f + 3.7f * 0.25f, 1e-6f);
}

TEST(DepthFusionUncertainty, AMeanBetweenTwoSurfacesDoesNotWeighAsAReturn) {
  // The case seen on the synthetic street: a real LiDAR return on the background (38 m) past
  // a pole that stereo sees at 27.8 m with a weak match, all within 3 sigma in disparity.
  // Averaged, the depth lies between the two surfaces; its weight must say so, while the free
  // space in front of both stays certain.
  const msf::DepthFusionConfig config; // the defaults
  const float fb = 389.f;              // KITTI's f B, px m
  msf::FusionInputs in;
  in.z_lidar = 38.f;
  in.lidar_edge_px = 4.f; // the pole's edge in the LiDAR's disparity
  in.z_stereo = 27.8f;
  in.stereo_confidence = 0.f;
  const auto f = msf::fuseUncertainty(in, config, fb);
  ASSERT_GT(f.z, in.z_stereo + 1.f); // averaged, between the surfaces
  ASSERT_LT(f.z, in.z_lidar - 1.f);
  const float real_return = 1.f / (config.lidar_range_sigma_m * config.lidar_range_sigma_m);
  EXPECT_GT(f.free_weight, real_return);  // the sum of the two
  EXPECT_LT(f.weight, 0.25f); // sigma of metres: below the integrator's min_pixel_weight
  // Where the two agree, the spread costs little: the road at 20 m, 2 cm apart.
  in.z_lidar = 20.f;
  in.z_stereo = 20.02f;
  in.lidar_edge_px = 0.f;
  in.stereo_confidence = 1.f;
  const auto g = msf::fuseUncertainty(in, config, fb);
  EXPECT_GT(g.weight, 0.5f * g.free_weight);
}

TEST(DepthFusionUncertainty, LidarEdgeCueBendIsZeroOnAPlaneAndTheStepAtAnEdge) {
  // A steep plane (the road: disparity affine in v, 0.4 px a row) and a step of 6 px in
  // disparity along the row. The bend is 0 on the plane however steep; the range is not.
  const int rows = 40, cols = 40;
  cv::Mat depth(rows, cols, CV_32FC1);
  for (int v = 0; v < rows; ++v)
    for (int u = 0; u < cols; ++u)
      depth.at<float>(v, u) = static_cast<float>(kFB / (10.0 + 0.4 * v + (u >= 20 ? 6.0 : 0.0)));
  cv::Mat bend, range;
  msf::localDisparityBend(depth, kFB, 2, bend);
  msf::localDisparityRange(depth, kFB, 5, range);
  EXPECT_NEAR(bend.at<float>(10, 5), 0.f, 1e-3f);
  EXPECT_NEAR(range.at<float>(10, 5), 1.6f, 1e-3f); // 4 rows of 0.4 px
  EXPECT_NEAR(bend.at<float>(10, 19), 6.f, 1e-3f);  // within the step of the edge
  EXPECT_NEAR(bend.at<float>(10, 20), 6.f, 1e-3f);
  EXPECT_NEAR(bend.at<float>(10, 22), 0.f, 1e-3f); // past it
  // A missing neighbour counts 0; a step < 1 is refused by name.
  depth.at<float>(10, 17) = 0.f;
  msf::localDisparityBend(depth, kFB, 2, bend);
  EXPECT_NEAR(bend.at<float>(10, 19), 0.f, 1e-3f);
  EXPECT_THROW(msf::localDisparityBend(depth, kFB, 0, bend), msf::InvalidInputError);
  // The configuration chooses the cue.
  msf::DepthFusionConfig config;
  cv::Mat cue;
  config.lidar_edge_cue = msf::LidarEdgeCue::Range;
  msf::lidarEdgeCue(depth, kFB, config, cue);
  EXPECT_NEAR(cue.at<float>(30, 5), 1.6f, 1e-3f);
  config.lidar_edge_cue = msf::LidarEdgeCue::Bend;
  msf::lidarEdgeCue(depth, kFB, config, cue);
  EXPECT_NEAR(cue.at<float>(30, 5), 0.f, 1e-3f);
}

TEST(DepthFusionUncertainty, WeightsAreInverseDepthVariancesThatTrustTheLidar) {
  // What the TSDF integrator averages with: 1 / sigma_z^2, sigma_z = z^2 sigma_d / (f B).
  const msf::DepthFusionConfig config; // the defaults
  const float fb = static_cast<float>(kFB);
  auto weight = [&](float z_lidar, float distance, float z_stereo, float confidence) {
    msf::FusionInputs in;
    in.z_lidar = z_lidar;
    in.lidar_distance = distance;
    in.z_stereo = z_stereo;
    in.stereo_confidence = confidence;
    return msf::fuseUncertainty(in, config, fb).weight;
  };
  const float lidar = weight(10.f, 0.f, 0.f, 1.f), stereo = weight(0.f, 0.f, 10.f, 1.f);
  // A real return: the LiDAR's range noise, at any depth.
  EXPECT_NEAR(lidar, 1.f / (config.lidar_range_sigma_m * config.lidar_range_sigma_m), 1e-3f * lidar);
  EXPECT_NEAR(weight(40.f, 0.f, 0.f, 1.f), lidar, 1e-3f * lidar);
  // The best stereo match: its disparity sigma in depth.
  const float sigma_stereo = 100.f * config.stereo_sigma_min_px / fb;
  EXPECT_NEAR(stereo, 1.f / (sigma_stereo * sigma_stereo), 1e-3f * stereo);
  EXPECT_GT(lidar, 10.f * stereo);
  // Both agreeing: more than either alone.
  EXPECT_GT(weight(10.f, 0.f, 10.f, 1.f), lidar);
  // Interpolated LiDAR far from a return, and weak stereo, weigh less.
  EXPECT_LT(weight(10.f, 20.f, 0.f, 1.f), lidar);
  EXPECT_LT(weight(0.f, 0.f, 10.f, 0.3f), stereo);
  // Depth error grows as z^2: twice as far, a sixteenth of the weight.
  EXPECT_NEAR(weight(0.f, 0.f, 20.f, 1.f), stereo / 16.f, 1e-4f * stereo);
  EXPECT_EQ(weight(0.f, 0.f, 0.f, 1.f), 0.f);
}

// A foreground box at 5 m fills the rows >= 10 of the image, a wall at 20 m the rows above.
// The LiDAR, 8 cm above the camera, sees over the box's top edge onto the wall: its returns
// in rows 10..15 are the wall's (f h (1/5 - 1/20) = 6 rows), where the camera sees the box.
// Stereo sees the box, a little less confident near the edge. The wall's LiDAR samples are
// real returns in every third column (distance 0 there, 1 between).
TEST(DepthFusionUncertainty, SyntheticEdgeKeepsTheForeground) {
  const int w = 12, h = 30, edge = 10;
  Inputs in(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const bool box = v >= edge;
      const bool seen_past_edge = box && v < edge + 6;
      in.setLidar(u, v, box && !seen_past_edge ? 5.f : 20.f, (u % 3 == 0) ? 0.f : 1.f);
      in.setStereo(u, v, box ? 5.f : 20.f, std::abs(v - edge) <= 2 ? 0.6f : 0.95f);
    }
  msf::DepthFusionConfig config = handMadeSigmas();
  config.method = msf::FusionMethod::Uncertainty;
  const FusedCloud out = fuse(in, config);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      EXPECT_NEAR(out.at(u, v).z, v >= edge ? 5.f : 20.f, 0.05f) << "pixel " << u << "," << v;
  // The same with the defaults measured on KITTI.
  const FusedCloud measured = fuse(in, msf::DepthFusionConfig{});
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      EXPECT_NEAR(measured.at(u, v).z, v >= edge ? 5.f : 20.f, 0.05f) << "pixel " << u << "," << v;
  // Without the parallax check the LiDAR's returns from the wall win where no foreground
  // return is within its 5 x 5 window (rows 10..12), as the LiDAR looks more certain there.
  config.parallax_check = false;
  EXPECT_NEAR(fuse(in, config).at(4, edge + 2).z, 20.f, 0.05f);
  // The paper's weighted mean puts those pixels between foreground and background.
  config.method = msf::FusionMethod::Paper;
  EXPECT_GT(fuse(in, config).at(4, edge + 2).z, 5.5f);
}

// Stereo nearer than a confident LiDAR, but the LiDAR has no such near surface below:
// no parallax case (a stereo mismatch, e.g. a fattened foreground), the LiDAR wins.
TEST(DepthFusionUncertainty, StereoNearerWithoutLidarEvidenceLoses) {
  const int w = 6, h = 20;
  Inputs in(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      in.setLidar(u, v, 20.f, 0.f);
      in.setStereo(u, v, v == 8 ? 5.f : 20.f, 0.7f);
    }
  EXPECT_NEAR(fuse(in, handMadeSigmas()).at(2, 8).z, 20.f, 1e-4f);
  EXPECT_NEAR(fuse(in, {}).at(2, 8).z, 20.f, 1e-4f);
}

// ---- organized invariants, colour, types -----------------------------------------------------

TEST(DepthFusion, OrganizedInvariants) {
  const int w = 7, h = 5;
  Inputs in(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if ((u + v) % 3 != 0)
        in.setLidar(u, v, 10.f + u, 1.f);
      if ((u + 2 * v) % 4 != 0)
        in.setStereo(u, v, 10.f + u, 0.9f);
    }
  in.stereo->header.frame_id = "camera_0";
  in.stereo->header.stamp = 42;
  for (auto method : {msf::FusionMethod::Paper, msf::FusionMethod::Uncertainty}) {
    msf::DepthFusionConfig config;
    config.method = method;
    const FusedCloud out = fuse(in, config);
    ASSERT_EQ(out.width, static_cast<std::uint32_t>(w));
    ASSERT_EQ(out.height, static_cast<std::uint32_t>(h));
    EXPECT_FALSE(out.is_dense);
    EXPECT_EQ(out.header.frame_id, "camera_0");
    EXPECT_EQ(out.header.stamp, 42u);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const bool any = (u + v) % 3 != 0 || (u + 2 * v) % 4 != 0;
        const auto& p = out.at(u, v);
        EXPECT_EQ(std::isfinite(p.z), any) << u << "," << v;
        EXPECT_EQ(std::isfinite(p.x), any);
        if (any) {
          EXPECT_NEAR(p.z, 10.f + u, 1e-4f);
          EXPECT_GT(p.weight, 0.f); // inverse variances in m^-2, eq. 6's trust scaled by the best stereo's
          EXPECT_EQ(p.r, 10); // colour of the stereo point
        } else {
          EXPECT_EQ(p.weight, 0.f);
        }
      }
  }
  // With depth everywhere the cloud is dense.
  Inputs full(3, 2);
  for (int v = 0; v < 2; ++v)
    for (int u = 0; u < 3; ++u)
      full.setStereo(u, v, 4.f, 1.f);
  EXPECT_TRUE(fuse(full, {}).is_dense);
}

TEST(DepthFusion, ColourImageColoursLidarOnlyPixels) {
  Inputs in(4, 3);
  in.setLidar(1, 1, 8.f, 0.f); // no stereo there
  cv::Mat color(3, 4, CV_8UC3, cv::Scalar(1, 2, 3));
  Fusion fusion;
  fusion.setCalibration(calibration(4, 3));
  fusion.setInputLidar(in.lidar);
  fusion.setInputStereo(in.stereo);
  fusion.setInputColor(color);
  FusedCloud out;
  fusion.fuse(out);
  EXPECT_EQ(out.at(1, 1).r, 3);
  EXPECT_EQ(out.at(1, 1).b, 1);
}

TEST(DepthFusion, PlainPointTypes) {
  // PointXYZ inputs: LiDAR points count as real returns, stereo points as confident.
  pcl::PointCloud<pcl::PointXYZ>::Ptr lidar(new pcl::PointCloud<pcl::PointXYZ>(2, 2)), stereo(new pcl::PointCloud<pcl::PointXYZ>(2, 2));
  for (int v = 0; v < 2; ++v)
    for (int u = 0; u < 2; ++u) {
      lidar->at(u, v) = onRay<pcl::PointXYZ>(u, v, 10.f, 2, 2);
      stereo->at(u, v) = onRay<pcl::PointXYZ>(u, v, u == 0 ? 10.2f : 0.f, 2, 2);
    }
  msf::DepthFusion<pcl::PointXYZ, pcl::PointXYZ, pcl::PointXYZ> fusion;
  fusion.setCalibration(calibration(2, 2));
  fusion.setInputLidar(lidar);
  fusion.setInputStereo(stereo);
  pcl::PointCloud<pcl::PointXYZ> out;
  fusion.fuse(out);
  EXPECT_NEAR(out.at(1, 0).z, 10.f, 1e-6f);
  EXPECT_GT(out.at(0, 0).z, 10.f);
  EXPECT_LT(out.at(0, 0).z, 10.2f);
}

TEST(DepthImageFusion, SameResultAsTheCloudClass) {
  const int w = 30, h = 8;
  Inputs in(w, h);
  cv::Mat zl(h, w, CV_32FC1, cv::Scalar(0)), dist(h, w, CV_32FC1, cv::Scalar(0)), zs(h, w, CV_32FC1, cv::Scalar(0)),
      conf(h, w, CV_32FC1, cv::Scalar(0));
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float z_l = (u * 7 + v) % 5 == 0 ? 0.f : 6.f + 0.3f * u + (u > 15 ? 10.f : 0.f);
      const float z_s = (u * 3 + v) % 7 == 0 ? 0.f : 6.2f + 0.3f * u + (u > 14 ? 10.f : 0.f);
      const float d = static_cast<float>((u + v) % 4), c = 0.1f * static_cast<float>((u * v) % 10);
      in.setLidar(u, v, z_l, d);
      in.setStereo(u, v, z_s, c);
      zl.at<float>(v, u) = z_l;
      dist.at<float>(v, u) = d;
      zs.at<float>(v, u) = z_s;
      conf.at<float>(v, u) = z_s > 0.f ? c : 0.f;
    }
  for (auto method : {msf::FusionMethod::Paper, msf::FusionMethod::Uncertainty}) {
    msf::DepthFusionConfig config;
    config.method = method;
    const FusedCloud cloud = fuse(in, config);
    cv::Mat fused, weight;
    msf::fuseDepthImages(zl, dist, zs, conf, calibration(w, h), config, fused, &weight);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const float z = cloud.at(u, v).z;
        EXPECT_NEAR(std::isfinite(z) ? z : 0.f, fused.at<float>(v, u), 1e-5f) << u << "," << v;
        EXPECT_NEAR(cloud.at(u, v).weight, weight.at<float>(v, u), 1e-6f);
      }
  }
}

TEST(DepthImageFusion, NoDepthInTheClearSkyTheCloudClassNeither) {
  // A blue sky over rows 0-19 (its blank part, eroded by the mask's border, rows 0-14) where
  // stereo matched 20 m everywhere, the LiDAR's returns (10 m) from row 24 down: the sky's depth
  // is withheld in both classes, given the colour image; with clear_sky off, or no image, it is
  // kept. A sky image of another size is refused.
  const int w = 60, h = 40;
  Inputs in(w, h);
  cv::Mat zl(h, w, CV_32FC1, cv::Scalar(0)), zs(h, w, CV_32FC1, cv::Scalar(20.f));
  cv::Mat colour(h, w, CV_8UC3, cv::Scalar(100, 100, 100));
  colour.rowRange(0, 20).setTo(cv::Scalar(230, 170, 120));
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if (v >= 24 && v % 2 == 0)
        zl.at<float>(v, u) = 10.f, in.setLidar(u, v, 10.f, 0.f);
      in.setStereo(u, v, 20.f, 1.f);
    }
  const auto sky = [&](const cv::Mat& depth) { return cv::countNonZero(depth.rowRange(0, 12) > 0.f); };
  msf::DepthImageFusion fusion;
  fusion.setCalibration(calibration(w, h));
  cv::Mat fused, weight;
  fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused, &weight);
  EXPECT_EQ(sky(fused), 12 * w);
  EXPECT_TRUE(fusion.getOpenSky().empty());
  fusion.setSkyImage(colour);
  fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused, &weight);
  EXPECT_EQ(sky(fused), 0);
  EXPECT_EQ(cv::countNonZero(weight.rowRange(0, 12)), 0);
  EXPECT_EQ(cv::countNonZero(fused.rowRange(24, h) > 0.f), (h - 24) * w); // below the sky: kept
  EXPECT_EQ(fusion.getOpenSky().at<std::uint8_t>(5, 30), 255);

  Fusion cloud_fusion;
  cloud_fusion.setCalibration(calibration(w, h));
  cloud_fusion.setInputLidar(in.lidar);
  cloud_fusion.setInputStereo(in.stereo);
  cloud_fusion.setInputColor(colour);
  FusedCloud cloud;
  cloud_fusion.fuse(cloud);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float z = cloud.at(u, v).z;
      ASSERT_EQ(std::isfinite(z) ? z : 0.f, fused.at<float>(v, u)) << u << "," << v;
    }

  msf::DepthFusionConfig off;
  off.clear_sky = false;
  fusion.setConfig(off);
  fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused, &weight);
  EXPECT_EQ(sky(fused), 12 * w);
  fusion.setConfig(msf::DepthFusionConfig());
  fusion.setSkyImage(colour.rowRange(0, h - 1));
  EXPECT_NE(msf::test::errorOf([&] { fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused); }).find("the sky image"),
            std::string::npos);
  // A weight of another size is refused before the depth is touched.
  cv::Mat depth = zs.clone(), small(h - 1, w, CV_32FC1, cv::Scalar(1.f)), none;
  EXPECT_THROW(msf::withholdClearSky(msf::SkyMask(), colour, cv::Mat(), zl, depth, small, none),
               msf::InvalidInputError);
  EXPECT_EQ(cv::countNonZero(depth != 20.f), 0);
}

TEST(DepthImageFusion, TheClearSkyBesideAThinPoleGivesNoDepthUpToItsTexture) {
  // A dark pole (columns 28-31) against a clipped white sky (rows 0-24), the LiDAR's returns
  // from row 28 down. Stereo widened the pole by 5 blank pixels a side (columns 23-36), as SGBM
  // does against a blank background. The depth is withheld up to the pixels whose 5x5 window
  // sees the pole (columns 26-27 and 32-33 keep it), not a mask's border short of them, and the
  // open sky holds the withheld pixels, so that the small-hole fill leaves them empty.
  const int w = 60, h = 40, pole_first = 28, pole_last = 31, widened = 5;
  cv::Mat zl(h, w, CV_32FC1, cv::Scalar(0)), zs(h, w, CV_32FC1, cv::Scalar(0));
  cv::Mat colour(h, w, CV_8UC3, cv::Scalar(100, 100, 100));
  colour.rowRange(0, 25).setTo(cv::Scalar(255, 255, 255));
  colour.colRange(pole_first, pole_last + 1).setTo(cv::Scalar(60, 60, 60));
  for (int v = 28; v < h; v += 2)
    zl.row(v).setTo(10.f);
  zs.rowRange(25, h).setTo(10.f);
  zs(cv::Range(0, 25), cv::Range(pole_first - widened, pole_last + widened + 1)).setTo(12.f);
  msf::DepthImageFusion fusion;
  fusion.setCalibration(calibration(w, h));
  fusion.setSkyImage(colour);
  cv::Mat fused, weight;
  fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused, &weight);
  fusion.fillSmallHoles(fused, &weight);
  const int row = 10;
  for (int u = pole_first - widened; u <= pole_last + widened; ++u) {
    const bool textured = u >= pole_first - 2 && u <= pole_last + 2; // the 5x5 window sees the pole
    EXPECT_EQ(fused.at<float>(row, u) > 0.f, textured) << "column " << u;
    EXPECT_EQ(fusion.getOpenSky().at<std::uint8_t>(row, u) != 0, !textured) << "column " << u;
  }
  // The mask's border still applies where nothing was withheld: the grey ground below the sky.
  EXPECT_EQ(fusion.getOpenSky().at<std::uint8_t>(24, 10), 0);
  EXPECT_EQ(fusion.getOpenSky().at<std::uint8_t>(row, 10), 255);
}

TEST(DepthImageFusion, TheSkyBesideANearPoleIsCameraZerosWhereTheColourCameraSeesThePoleShifted) {
  // Camera 0 sees a dark pole at columns 28-31 against a clipped white sky (rows 0-24); the
  // colour camera beside it sees the pole 3 columns to the right, by their parallax. Stereo
  // widened the pole by 5 pixels a side in camera 0 (columns 23-36). Given camera 0's grey image,
  // the depth is withheld up to the pole's own columns: its clipped sky decides, the pixels
  // beside the pole that its texture window keeps out of the mask included. Neither the pole's
  // left edge, where the colour camera sees sky, nor the sky to its right, where the colour
  // camera sees the pole, is decided by the colour image alone.
  const int w = 60, h = 40, pole_first = 28, pole_last = 31, parallax = 3, widened = 5;
  cv::Mat grey(h, w, CV_8UC1, cv::Scalar(100));
  grey.rowRange(0, 25).setTo(255);
  cv::Mat colour;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  grey.colRange(pole_first, pole_last + 1).setTo(60);
  colour.colRange(pole_first + parallax, pole_last + parallax + 1).setTo(cv::Scalar(60, 60, 60));
  cv::Mat zl(h, w, CV_32FC1, cv::Scalar(0)), zs(h, w, CV_32FC1, cv::Scalar(0));
  for (int v = 28; v < h; v += 2)
    zl.row(v).setTo(10.f);
  zs.rowRange(25, h).setTo(10.f);
  zs(cv::Range(0, 25), cv::Range(pole_first - widened, pole_last + widened + 1)).setTo(12.f);
  msf::DepthFusionConfig config;
  config.facade_extension = false; // the pole's columns keep stereo's depth
  msf::DepthImageFusion fusion(config);
  fusion.setCalibration(calibration(w, h));
  fusion.setSkyImage(colour);
  const auto keptAtRow10 = [&](const cv::Mat& left) {
    fusion.setInputImage(left);
    cv::Mat fused;
    fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused);
    std::vector<int> kept;
    for (int u = 0; u < w; ++u)
      if (fused.at<float>(10, u) > 0.f)
        kept.push_back(u);
    return kept;
  };
  std::vector<int> pole_in_camera_0;
  for (int u = pole_first; u <= pole_last; ++u)
    pole_in_camera_0.push_back(u);
  EXPECT_EQ(keptAtRow10(grey), pole_in_camera_0);
  // The colour image alone takes the pole's left edge for sky and keeps the sky to its right.
  const std::vector<int> by_colour_alone = keptAtRow10(cv::Mat());
  EXPECT_EQ(by_colour_alone.front(), pole_first + parallax - 2);
  EXPECT_EQ(by_colour_alone.back(), pole_last + widened);
  // A grey image of another size is refused.
  cv::Mat depth = zs.clone(), none;
  EXPECT_THROW(msf::withholdClearSky(msf::SkyMask(), colour, grey.rowRange(0, h - 1), zl, depth, none, none),
               msf::InvalidInputError);
}

TEST(DepthImageFusion, StereoCarriedFromAPoleOverAPaleSkyIsWithheldWhereABlankWallKeepsItsDepth) {
  // A pale, grey-white sky (neither clipped nor blue: a blank wall may look so) over rows 0-29.
  // A dark pole at columns 28-31, its LiDAR returns (10 m) from row 26 down; a blank wall of the
  // sky's colour at columns 55-79, its returns (20 m) from row 26 down; between them the returns
  // of a building 30 m away from row 32 down. Stereo widened the pole by 5 pixels a side over
  // the sky (columns 23-36) and matched the wall above its returns. The widened pixels past the
  // pole's texture lie in front of the building's returns on their other side: withheld, and
  // held in the open sky. The wall's pixels lie at their column's returns: kept.
  const int w = 80, h = 40, pole_first = 28, pole_last = 31, widened = 5, wall_first = 55;
  cv::Mat colour(h, w, CV_8UC3, cv::Scalar(100, 100, 100));
  colour.rowRange(0, 30).setTo(cv::Scalar(235, 215, 200));
  colour.colRange(pole_first, pole_last + 1).setTo(cv::Scalar(60, 60, 60));
  cv::Mat zl(h, w, CV_32FC1, cv::Scalar(0)), zs(h, w, CV_32FC1, cv::Scalar(0));
  for (int v = 26; v < h; v += 2) {
    zl(cv::Range(v, v + 1), cv::Range(pole_first, pole_last + 1)).setTo(10.f);
    zl(cv::Range(v, v + 1), cv::Range(wall_first, w)).setTo(20.f);
    if (v >= 32) {
      zl(cv::Range(v, v + 1), cv::Range(0, pole_first)).setTo(30.f);
      zl(cv::Range(v, v + 1), cv::Range(pole_last + 1, wall_first)).setTo(30.f);
    }
  }
  zs(cv::Range(0, 30), cv::Range(pole_first - widened, pole_last + widened + 1)).setTo(10.f);
  zs(cv::Range(0, 30), cv::Range(wall_first, w)).setTo(20.f);
  msf::DepthImageFusion fusion;
  fusion.setCalibration(calibration(w, h));
  fusion.setSkyImage(colour);
  cv::Mat fused, weight;
  fusion.fuse(zl, cv::Mat(), zs, cv::Mat(), fused, &weight);
  const int row = 10;
  for (int u = pole_first - widened; u <= pole_last + widened; ++u) {
    const bool textured = u >= pole_first - 2 && u <= pole_last + 2; // the 5x5 window sees the pole
    EXPECT_EQ(fused.at<float>(row, u) > 0.f, textured) << "column " << u;
    EXPECT_EQ(weight.at<float>(row, u) > 0.f, textured) << "column " << u;
    EXPECT_EQ(fusion.getOpenSky().at<std::uint8_t>(row, u) != 0, !textured) << "column " << u;
  }
  for (int u = wall_first; u < w; ++u)
    EXPECT_NEAR(fused.at<float>(row, u), 20.f, 0.01f) << "column " << u;
  EXPECT_NE(fusion.getOpenSky().at<std::uint8_t>(row, 70), 0); // the wall taken for sky
}

TEST(LocalDisparityRange, MaxMinusMinOfValidNeighbours) {
  cv::Mat depth(3, 5, CV_32FC1, cv::Scalar(0));
  depth.at<float>(1, 1) = static_cast<float>(kFB / 10.0); // disparity 10
  depth.at<float>(1, 3) = static_cast<float>(kFB / 4.0);  // disparity 4
  cv::Mat range;
  msf::localDisparityRange(depth, kFB, 3, range);
  EXPECT_NEAR(range.at<float>(1, 2), 6.f, 1e-4f); // sees both
  EXPECT_NEAR(range.at<float>(1, 0), 0.f, 1e-6f); // sees one
  EXPECT_NEAR(range.at<float>(0, 4), 0.f, 1e-6f); // sees one
  EXPECT_THROW(msf::localDisparityRange(depth, kFB, 4, range), msf::InvalidInputError);
}

// ---- bad input -----------------------------------------------------------------------------

using msf::test::errorOf;

TEST(DepthFusion, BadInputNamesWhatIsWrong) {
  Inputs a(6, 4), b(5, 4);
  Fusion fusion;
  FusedCloud out;
  fusion.setCalibration(calibration(6, 4));
  // Missing inputs.
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("LiDAR cloud is missing"), std::string::npos);
  fusion.setInputLidar(a.lidar);
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("stereo cloud is missing"), std::string::npos);
  // Clouds of different sizes.
  fusion.setInputStereo(b.stereo);
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("LiDAR cloud is 6x4 but the stereo cloud is 5x4"),
            std::string::npos);
  // Both clouds of one size, which is not the rig's: fused, they would be at shifted pixels.
  Inputs small(4, 2);
  fusion.setInputLidar(small.lidar);
  fusion.setInputStereo(small.stereo);
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("stereo cloud is 4x2 but calibration"), std::string::npos);
  // A stereo depth whose confidence is NaN would weigh NaN.
  Inputs nan_confidence(6, 4);
  nan_confidence.setStereo(2, 1, 5.f, 0.5f);
  nan_confidence.stereo->at(2, 1).confidence = std::numeric_limits<float>::quiet_NaN();
  fusion.setInputLidar(nan_confidence.lidar);
  fusion.setInputStereo(nan_confidence.stereo);
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("stereo cloud's confidence at pixel (2, 1) is nan"),
            std::string::npos);
  nan_confidence.stereo->at(2, 1).confidence = 0.5f;
  EXPECT_NO_THROW(fusion.fuse(out));
  fusion.setInputLidar(a.lidar);
  // An unorganized cloud.
  StereoCloud::Ptr flat(new StereoCloud(*a.stereo));
  flat->width = 24;
  flat->height = 1;
  fusion.setInputStereo(flat);
  EXPECT_NE(errorOf([&] { fusion.fuse(out); }).find("stereo cloud is not organized"), std::string::npos);
  // No calibration.
  Fusion uncalibrated;
  uncalibrated.setInputLidar(a.lidar);
  uncalibrated.setInputStereo(a.stereo);
  EXPECT_THROW(uncalibrated.fuse(out), msf::CalibrationError);
  // Images of different sizes.
  cv::Mat z6(4, 6, CV_32FC1, cv::Scalar(1)), z5(4, 5, CV_32FC1, cv::Scalar(1)), fused;
  const msf::Calibration c = calibration(6, 4);
  EXPECT_NE(errorOf([&] { msf::fuseDepthImages(z6, cv::Mat(), z5, cv::Mat(), c, {}, fused); })
                .find("stereo depth image is 5x4 but the LiDAR depth is 6x4"),
            std::string::npos);
  EXPECT_THROW(msf::fuseDepthImages(z6, cv::Mat(4, 6, CV_8UC1), z6, cv::Mat(), c, {}, fused), msf::InvalidInputError);
}

TEST(DepthFusionConfig, ReadsTheFusionSectionAndRejectsBadValues) {
  msf::test::TempDir dir;
  const std::string path = dir.file("c.yaml");
  std::ofstream(path) << "%YAML:1.0\nfusion:\n  method: paper\n  paper_lidar_gain: 2.5\n  disagreement_k_sigma: 4\n";
  msf::DepthFusionConfig config;
  msf::ConfigFile(path).read(config);
  EXPECT_EQ(config.method, msf::FusionMethod::Paper);
  EXPECT_FLOAT_EQ(config.paper_lidar_gain, 2.5f);
  EXPECT_FLOAT_EQ(config.disagreement_k_sigma, 4.f);
  EXPECT_FLOAT_EQ(config.stereo_sigma_min_px, msf::DepthFusionConfig{}.stereo_sigma_min_px); // default kept
  std::ostringstream printed;
  msf::printConfig(printed, config);
  EXPECT_NE(printed.str().find("method: paper"), std::string::npos);
  auto fails = [&](const std::string& body, const std::string& key) {
    std::ofstream(path) << "%YAML:1.0\nfusion:\n  " << body << "\n";
    return errorOf([&] {
             msf::DepthFusionConfig c;
             msf::ConfigFile(path).read(c);
           }).find(key) != std::string::npos;
  };
  EXPECT_TRUE(fails("method: average", "fusion.method"));
  EXPECT_TRUE(fails("stereo_sigma_min_px: 0", "fusion.stereo_sigma_min_px"));
  EXPECT_TRUE(fails("stereo_sigma_max_px: 0.1", "fusion.stereo_sigma_max_px"));
  EXPECT_TRUE(fails("lidar_range_window_px: 4", "fusion.lidar_range_window_px"));
  EXPECT_TRUE(fails("lidar_edge_cue: slope", "fusion.lidar_edge_cue"));
  EXPECT_TRUE(fails("disagreement_k_sigma: many", "fusion.disagreement_k_sigma"));
}

} // namespace
