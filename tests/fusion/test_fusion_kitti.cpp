// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Fusion on real KITTI frames under protocol 2 (docs/design.md) (ring hold-out): the fused depth
// must beat each of its inputs, and the rows of msf_holdout must say so too.
#include <msf/evaluation/depth_metrics.h>
#include <msf/evaluation/holdout.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/depth_image_fusion.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/sequence.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/stereo/sgbm_stereo.h>

#include "test_support.h"

#include <sstream>

namespace {

std::string sequenceDir() { return msf::test::kittiDir() + "/odometry/sequences/04"; }

TEST(FusionKitti, FusedBeatsEachInputOnHeldOutRings) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(sequenceDir());
  const msf::Calibration& calibration = sequence.calibration();
  msf::LidarCompletion lidar(calibration);
  msf::SgbmStereo stereo;
  stereo.setCalibration(calibration);
  const double fB = calibration.focalBaseline();
  msf::DepthErrorAccumulator lidar_errors, stereo_errors, paper_errors, uncertainty_errors, no_edge_errors;
  for (std::size_t i : {0u, 5u}) {
    const msf::HoldoutFrame frame = msf::makeHoldoutFrame(sequence.load(i, false), calibration, {});
    cv::Mat lidar_depth, distance;
    lidar.computeDepth(*frame.input.scan, lidar_depth, &distance);
    stereo.setInputImages(frame.input.left, frame.input.right);
    stereo.setDepthPrior(lidar_depth);
    stereo.computeDisparity();
    const cv::Mat stereo_depth = stereo.getDepth();
    cv::Mat paper, uncertainty;
    msf::DepthFusionConfig config;
    config.method = msf::FusionMethod::Paper;
    msf::fuseDepthImages(lidar_depth, distance, stereo_depth, stereo.getConfidence(), calibration, config, paper);
    config.method = msf::FusionMethod::Uncertainty;
    msf::fuseDepthImages(lidar_depth, distance, stereo_depth, stereo.getConfidence(), calibration, config, uncertainty);
    cv::Mat no_edge;
    config.edge_support = false;
    msf::fuseDepthImages(lidar_depth, distance, stereo_depth, stereo.getConfidence(), calibration, config, no_edge);
    no_edge_errors.add(frame.gt_depth, no_edge, fB);
    lidar_errors.add(frame.gt_depth, lidar_depth, fB);
    stereo_errors.add(frame.gt_depth, stereo_depth, fB);
    paper_errors.add(frame.gt_depth, paper, fB);
    uncertainty_errors.add(frame.gt_depth, uncertainty, fB);
  }
  const auto l = lidar_errors.metrics(), s = stereo_errors.metrics(), p = paper_errors.metrics(),
             u = uncertainty_errors.metrics();
  ASSERT_GT(u.gt_pixels, 8000u);
  // Both fusions cover more than either input and have fewer D1 outliers.
  for (const auto& fused : {p, u}) {
    EXPECT_GT(fused.coverage, std::max(l.coverage, s.coverage));
    EXPECT_GT(fused.coverage, 0.99);
    EXPECT_LT(fused.d1_all, l.d1_all);
    EXPECT_LT(fused.d1_all, s.d1_all);
  }
  // The default (uncertainty) is the better fusion, and is more accurate than each input.
  EXPECT_LT(u.d1_all, p.d1_all);
  EXPECT_LT(u.disparity_mae_px, std::min(l.disparity_mae_px, s.disparity_mae_px));
  EXPECT_LT(u.mae_m, s.mae_m);
  EXPECT_LT(u.d1_all, 0.045);
  // Edge support removes outliers between the surfaces of depth edges.
  EXPECT_LT(u.d1_all, no_edge_errors.metrics().d1_all);
}

// The cloud class and the image function agree on a real frame.
TEST(FusionKitti, CloudClassMatchesImageFunction) {
  MSF_REQUIRE_KITTI();
  const msf::Sequence sequence(sequenceDir());
  const msf::Calibration& calibration = sequence.calibration();
  const msf::Frame frame = sequence.load(3, true);
  msf::LidarCompletion lidar(calibration);
  pcl::PointCloud<msf::PointXYZID>::Ptr lidar_cloud(new pcl::PointCloud<msf::PointXYZID>);
  lidar.compute(*frame.scan, *lidar_cloud);
  msf::SgbmStereo stereo;
  stereo.setCalibration(calibration);
  stereo.setInputImages(frame.left, frame.right);
  stereo.setInputColor(frame.color);
  const cv::Mat lidar_depth = msf::cloudToDepthImage(*lidar_cloud);
  stereo.setDepthPrior(lidar_depth);
  pcl::PointCloud<msf::PointXYZRGBConfidence>::Ptr stereo_cloud(new pcl::PointCloud<msf::PointXYZRGBConfidence>);
  stereo.compute(*stereo_cloud);

  msf::DepthFusion<> fusion;
  fusion.setCalibration(calibration);
  fusion.setInputLidar(lidar_cloud);
  fusion.setInputStereo(stereo_cloud);
  pcl::PointCloud<msf::PointXYZRGBWeight> fused;
  fusion.fuse(fused);
  ASSERT_EQ(fused.width, 1226u);
  ASSERT_EQ(fused.height, 370u);
  // Headers: the scan's stamp (microseconds from the first frame, times.txt) and frame id,
  // carried through every stage into camera 0's frame.
  EXPECT_EQ(frame.scan->header.frame_id, "velodyne");
  EXPECT_NEAR(static_cast<double>(frame.scan->header.stamp), frame.timestamp * 1e6, 1.0);
  EXPECT_GT(frame.scan->header.stamp, 0u);
  for (const auto* header : {&lidar_cloud->header, &fused.header}) {
    EXPECT_EQ(header->frame_id, "camera_0");
    EXPECT_EQ(header->stamp, frame.scan->header.stamp);
  }
  EXPECT_EQ(stereo_cloud->header.frame_id, "camera_0");

  cv::Mat distance(lidar_depth.size(), CV_32FC1);
  for (int v = 0; v < distance.rows; ++v)
    for (int u = 0; u < distance.cols; ++u)
      distance.at<float>(v, u) = lidar_cloud->at(u, v).distance;
  cv::Mat image;
  msf::fuseDepthImages(lidar_depth, distance, stereo.getDepth(), stereo.getConfidence(), calibration, {}, image);
  std::size_t differ = 0, valid = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) {
      const float z = fused.at(u, v).z;
      valid += std::isfinite(z);
      differ += std::fabs((std::isfinite(z) ? z : 0.f) - image.at<float>(v, u)) > 1e-3f * image.at<float>(v, u) + 1e-4f;
    }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(valid, 0.9 * image.total());
}

TEST(FusionKitti, HoldoutToolHasTheStereoAndFusedRows) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const auto r = msf::test::runTool("msf_holdout", sequenceDir() + " -frames 2:2 -methods interpolated,sgbm,fused_paper,"
                                                   "fused_uncertainty -csv " + dir.file("t.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* row : {"\nsgbm ", "\nfused_paper ", "\nfused_uncertainty "})
    EXPECT_NE(r.out.find(row), std::string::npos) << row << " in\n" << r.out;
  EXPECT_TRUE(msf::test::fileExists(dir.file("t.csv")));
}

} // namespace
