// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/confidence_calibration.h>
#include <msf/fusion/fusion_model.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/point_types.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

void writeTextFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// The robust sigma column of the tool's row for the confidence bin `range` ("0.90-0.97"), -1 without one.
double robustSigmaOfRow(const std::string& out, const std::string& range) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(range, 0) == 0) {
      std::istringstream fields(line.substr(range.size()));
      double pixels, mean_confidence, median, robust_sigma;
      if (fields >> pixels >> mean_confidence >> median >> robust_sigma)
        return robust_sigma;
    }
  return -1.0;
}

/// A 400x500 frame of true disparity 30 px: the top half at confidence 0.95 with Gaussian
/// errors of sigma 0.3 px, the bottom half at confidence 0.1 with sigma 1.2 px and every
/// tenth pixel an outlier 10 px off. Row 0 has no ground truth, row 1 no estimate.
struct Frame {
  cv::Mat gt, est, confidence;
  Frame() : gt(400, 500, CV_32FC1, cv::Scalar(30.f)), est(gt.size(), CV_32FC1), confidence(gt.size(), CV_32FC1) {
    cv::RNG rng(7);
    for (int v = 0; v < gt.rows; ++v)
      for (int u = 0; u < gt.cols; ++u) {
        const bool sure = v < gt.rows / 2;
        confidence.at<float>(v, u) = sure ? 0.95f : 0.1f;
        const bool outlier = !sure && (u + v * gt.cols) % 10 == 0;
        est.at<float>(v, u) = 30.f + (outlier ? 10.f : static_cast<float>(rng.gaussian(sure ? 0.3 : 1.2)));
      }
    gt.row(0).setTo(0.f);
    est.row(1).setTo(std::nanf(""));
  }
};

TEST(ConfidenceCalibration, MeasuresTheSigmaOfEachConfidenceBin) {
  const Frame f;
  msf::ConfidenceCalibration calibration({0.f, 0.5f, 1.f});
  calibration.add(f.gt, f.est, f.confidence);
  calibration.add(f.gt, f.est, f.confidence); // a sequence: the pixels of both frames
  EXPECT_EQ(calibration.pixels(), 2u * 398u * 500u);

  msf::DepthFusionConfig model;
  const auto rows = calibration.rows(model);
  ASSERT_EQ(rows.size(), 2u);
  const auto& low = rows[0];
  const auto& high = rows[1];
  EXPECT_EQ(high.pixels, 2u * 198u * 500u);
  EXPECT_EQ(low.pixels, 2u * 200u * 500u);
  EXPECT_NEAR(high.mean_confidence, 0.95, 1e-6);
  EXPECT_NEAR(high.median_px, 0.0, 0.01);
  EXPECT_NEAR(high.robust_sigma_px, 0.3, 0.01);
  EXPECT_NEAR(high.outlier_share, 0.0, 1e-9); // 10 sigma
  EXPECT_NEAR(high.model_sigma_px, msf::stereoSigmaPx(0.95f, model), 1e-6);
  // The outliers move the robust figures a little, as they do the mixture 0.9 N(0, 1.2^2) +
  // 0.1 at 10 px: its median is 1.2 x the normal's 0.5 / 0.9 quantile, 0.168 px, and
  // 1.4826 x its median absolute deviation 1.374 px (solved numerically).
  EXPECT_NEAR(low.median_px, 0.168, 0.02);
  EXPECT_NEAR(low.robust_sigma_px, 1.374, 0.03);
  // Beyond 3 px: the outliers and the Gaussian's tail beyond 2.5 sigma (1.24 %).
  EXPECT_NEAR(low.outlier_share, 0.1 + 0.9 * 0.0124, 0.003);
  EXPECT_NEAR(low.model_sigma_px, msf::stereoSigmaPx(0.1f, model), 1e-6);

  // The model's sigmas come from the fusion's configuration.
  model.stereo_sigma_min_px = 0.3f;
  EXPECT_NEAR(calibration.rows(model)[1].model_sigma_px, msf::stereoSigmaPx(0.95f, model), 1e-6);
}

TEST(ConfidenceCalibration, AnEmptyBinAndBadInput) {
  const Frame f;
  msf::ConfidenceCalibration calibration({0.f, 0.05f, 0.5f, 1.f});
  calibration.add(f.gt, f.est, f.confidence);
  const auto rows = calibration.rows(msf::DepthFusionConfig());
  EXPECT_EQ(rows[0].pixels, 0u);
  EXPECT_EQ(rows[0].robust_sigma_px, 0.0);

  EXPECT_THROW(msf::ConfidenceCalibration({0.5f}), msf::InvalidInputError);
  EXPECT_THROW(msf::ConfidenceCalibration({0.f, 0.5f, 0.4f}), msf::InvalidInputError);
  EXPECT_THROW(msf::ConfidenceCalibration({0.f, 1.5f}), msf::InvalidInputError);
  EXPECT_THROW(calibration.rows(msf::DepthFusionConfig(), 0.f), msf::InvalidInputError);
  const std::string wrong_size = msf::test::errorOf([&] { calibration.add(f.gt, f.est, f.confidence.rowRange(0, 10)); });
  EXPECT_NE(wrong_size.find("the confidence is 500x10 but the ground truth is 500x400"), std::string::npos)
      << wrong_size;
  cv::Mat eight;
  f.est.convertTo(eight, CV_8UC1);
  EXPECT_THROW(calibration.add(f.gt, eight, f.confidence), msf::InvalidInputError);
}

/// The frame as the tool reads it: KITTI disparity PNGs and the estimate's organized cloud.
void writeFrame(const Frame& f, const std::string& gt_png, const std::string& est_png, const std::string& cloud_pcd) {
  msf::writeKittiDisparityPng(gt_png, f.gt);
  msf::writeKittiDisparityPng(est_png, f.est);
  pcl::PointCloud<msf::PointXYZRGBConfidence> cloud(f.gt.cols, f.gt.rows);
  for (int v = 0; v < f.gt.rows; ++v)
    for (int u = 0; u < f.gt.cols; ++u)
      cloud(u, v).confidence = f.confidence.at<float>(v, u);
  msf::saveCloud(cloud_pcd, cloud);
}

/// Folder mode: gt/000000.png, est/000000.png and conf/<cloud_name>; the tool's arguments.
std::string writeFolders(const Frame& f, const msf::test::TempDir& tmp, const std::string& cloud_name) {
  for (const char* d : {"gt", "est", "conf"})
    std::filesystem::create_directories(tmp.file(d));
  writeFrame(f, tmp.file("gt/000000.png"), tmp.file("est/000000.png"), tmp.file("conf/" + cloud_name));
  return tmp.file("gt") + " " + tmp.file("est") + " -confidence " + tmp.file("conf");
}

TEST(EvalDisparityTool, ErrorByConfidenceBesideTheFusionSigma) {
  const Frame f;
  msf::test::TempDir tmp;
  writeFrame(f, tmp.file("gt.png"), tmp.file("est.png"), tmp.file("est.pcd"));
  auto r = msf::test::runTool("msf_eval_disparity",
                              tmp.file("gt.png") + " " + tmp.file("est.png") + " -confidence " + tmp.file("est.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("error by stereo confidence (the fusion's sigma: 0.35 px at confidence 1, 1.75 px at 0)"),
            std::string::npos)
      << r.out;
  // The bins of 0.1 and 0.95 (the PNGs keep 1/256 px).
  EXPECT_NEAR(robustSigmaOfRow(r.out, "0.00-0.20"), 1.374, 0.03) << r.out;
  EXPECT_NEAR(robustSigmaOfRow(r.out, "0.90-0.97"), 0.3, 0.01) << r.out;
  // A config's sigma model.
  writeTextFile(tmp.file("c.yaml"), "%YAML:1.0\nfusion:\n  stereo_sigma_min_px: 0.25\n  stereo_sigma_max_px: 1.25\n");
  r = msf::test::runTool("msf_eval_disparity", tmp.file("gt.png") + " " + tmp.file("est.png") + " -confidence " +
                                                   tmp.file("est.pcd") + " -config " + tmp.file("c.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("0.25 px at confidence 1, 1.25 px at 0"), std::string::npos) << r.out;

  // Folders: the clouds as NNNNNN.pcd, the same figures.
  r = msf::test::runTool("msf_eval_disparity", writeFolders(f, tmp, "000000.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(robustSigmaOfRow(r.out, "0.00-0.20"), 1.374, 0.03) << r.out;
  EXPECT_NEAR(robustSigmaOfRow(r.out, "0.90-0.97"), 0.3, 0.01) << r.out;
}

TEST(EvalDisparityTool, ConfidenceBadInput) {
  const Frame f;
  msf::test::TempDir tmp;
  writeFrame(f, tmp.file("gt.png"), tmp.file("est.png"), tmp.file("est.pcd"));
  const std::string pair = tmp.file("gt.png") + " " + tmp.file("est.png");
  // A cloud of another size.
  pcl::PointCloud<msf::PointXYZRGBConfidence> small(10, 10);
  msf::saveCloud(tmp.file("small.pcd"), small);
  auto r = msf::test::runTool("msf_eval_disparity", pair + " -confidence " + tmp.file("small.pcd"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("is 10x10 but the ground truth is 500x400"), std::string::npos) << r.err;
  // A missing cloud, and a folder for one frame.
  r = msf::test::runTool("msf_eval_disparity", pair + " -confidence " + tmp.file("none.pcd"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("none.pcd"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_eval_disparity", pair + " -confidence " + tmp.path());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("must be a .pcd file, as the estimate is one frame"), std::string::npos) << r.err;
  // Folders without the frame's cloud.
  r = msf::test::runTool("msf_eval_disparity", writeFolders(f, tmp, "000001.pcd"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("000000.pcd' for estimate"), std::string::npos) << r.err;
  // A sigma model without -confidence to use it.
  writeTextFile(tmp.file("c.yaml"), "%YAML:1.0\nfusion:\n  stereo_sigma_min_px: 0.25\n");
  r = msf::test::runTool("msf_eval_disparity", pair + " -config " + tmp.file("c.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-config gives the sigma model of -confidence"), std::string::npos) << r.err;
  // No pixel with a confidence in [0, 1].
  Frame none;
  none.confidence.setTo(std::nanf(""));
  writeFrame(none, tmp.file("gt2.png"), tmp.file("est2.png"), tmp.file("est2.pcd"));
  r = msf::test::runTool("msf_eval_disparity",
                         tmp.file("gt2.png") + " " + tmp.file("est2.png") + " -confidence " + tmp.file("est2.pcd"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no pixel has a ground truth, an estimate and a confidence"), std::string::npos) << r.err;
}

} // namespace
