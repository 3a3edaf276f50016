// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/image_io.h>
#include <msf/io/velodyne_io.h>
#include <msf/stereo/disparity_search_range.h>
#include <msf/stereo/point_types.h>
#include <msf/stereo/sgbm_stereo.h>
#include <msf/stereo/stereo_confidence.h>

#include "stereo_scenes.h"
#include "test_support.h"

#include <opencv2/imgcodecs.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <fstream>

namespace {

using msf::PointXYZRGBConfidence;

const cv::Size kSize(320, 160);

/// Median of the valid disparities inside `roi`.
float medianIn(const cv::Mat& disparity, const cv::Rect& roi) {
  std::vector<float> values;
  for (int v = roi.y; v < roi.y + roi.height; ++v)
    for (int u = roi.x; u < roi.x + roi.width; ++u)
      if (disparity.at<float>(v, u) > 0.f)
        values.push_back(disparity.at<float>(v, u));
  if (values.empty())
    return 0.f;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

msf::SgbmConfig smallConfig() {
  msf::SgbmConfig config;
  config.num_disparities_px = 48;
  return config;
}

TEST(SgbmStereo, RecoversTheDisparityOfTwoPlanes) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SgbmConfig bordered = smallConfig();
  bordered.match_left_border = true;
  msf::SgbmStereo stereo(bordered);
  stereo.setInputImages(pair.left, pair.right);
  stereo.computeDisparity();
  const cv::Mat& d = stereo.getDisparity();
  ASSERT_EQ(d.size(), kSize);
  ASSERT_EQ(d.type(), CV_32FC1);
  // Interior of the background (right of the search band, left of the square) and of the square.
  EXPECT_NEAR(medianIn(d, cv::Rect(60, 20, 80, 120)), 12.f, 0.1f);
  const cv::Rect inner(pair.square.x + 8, pair.square.y + 8, pair.square.width - 16, pair.square.height - 16);
  EXPECT_NEAR(medianIn(d, inner), 30.f, 0.1f);
  EXPECT_EQ(stereo.getSearchedDisparities(), 48);
  // The left border is matched too (the pair is padded), but never with a disparity that
  // points outside the right image.
  EXPECT_NEAR(medianIn(d, cv::Rect(16, 20, 24, 120)), 12.f, 0.1f);
  for (int v = 0; v < d.rows; ++v)
    for (int u = 0; u < d.cols; ++u)
      ASSERT_LE(d.at<float>(v, u), static_cast<float>(u)) << u << "," << v;
  // Without it, OpenCV leaves the first num_disparities columns empty.
  msf::SgbmConfig config = smallConfig();
  config.match_left_border = false;
  msf::SgbmStereo plain(config);
  plain.setInputImages(pair.left, pair.right);
  plain.computeDisparity();
  EXPECT_EQ(cv::countNonZero(plain.getDisparity().colRange(0, 40) > 0.f), 0);
  EXPECT_NEAR(medianIn(plain.getDisparity(), cv::Rect(60, 20, 80, 120)), 12.f, 0.1f);
}

TEST(SgbmStereo, OrganizedCloudWithDepthColourAndConfidence) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  const msf::Calibration calibration = msf::test::syntheticCalibration(kSize, 500.0, 0.5);
  cv::Mat color(kSize, CV_8UC3, cv::Scalar(10, 20, 30)); // BGR
  msf::SgbmStereo stereo(smallConfig());
  stereo.setCalibration(calibration);
  stereo.setInputImages(pair.left, pair.right);
  stereo.setInputColor(color);
  pcl::PointCloud<PointXYZRGBConfidence> cloud;
  stereo.compute(cloud);
  ASSERT_EQ(cloud.width, static_cast<std::uint32_t>(kSize.width));
  ASSERT_EQ(cloud.height, static_cast<std::uint32_t>(kSize.height));
  EXPECT_FALSE(cloud.is_dense);
  const cv::Mat& d = stereo.getDisparity();
  std::size_t nan_where_no_disparity = 0, finite_where_disparity = 0, invalid = 0;
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < kSize.width; ++u) {
      const auto& p = cloud.at(u, v);
      if (d.at<float>(v, u) > 0.f) {
        ++finite_where_disparity;
        EXPECT_NEAR(p.z, 250.f / d.at<float>(v, u), 1e-3f); // f B / d
        EXPECT_NEAR(p.x, (u - 160.f) * p.z / 500.f, 1e-3f);
        EXPECT_NEAR(p.y, (v - 80.f) * p.z / 500.f, 1e-3f);
        EXPECT_EQ(p.r, 30);
        EXPECT_EQ(p.g, 20);
        EXPECT_EQ(p.b, 10);
        EXPECT_GT(p.confidence, 0.f);
        EXPECT_LE(p.confidence, 1.f);
      } else {
        ++invalid;
        nan_where_no_disparity += std::isnan(p.x) && std::isnan(p.y) && std::isnan(p.z);
        EXPECT_EQ(p.confidence, 0.f);
      }
    }
  EXPECT_EQ(nan_where_no_disparity, invalid);
  EXPECT_GT(finite_where_disparity, static_cast<std::size_t>(0.8 * kSize.area()));
  // Background plane at f B / 12 = 20.8 m; the square at 250 / 30 = 8.33 m.
  EXPECT_NEAR(cloud.at(100, 80).z, 250.f / 12.f, 0.2f);
  EXPECT_NEAR(cloud.at(pair.square.x + pair.square.width / 2, 80).z, 250.f / 30.f, 0.05f);
  // Deep inside a flat region confidence is high; next to the square's edge it is lower.
  EXPECT_GT(cloud.at(100, 80).confidence, 0.9f);
  EXPECT_LT(cloud.at(pair.square.x - 1, 80).confidence, cloud.at(100, 80).confidence);
}

TEST(SgbmStereo, WithoutColourImageTheCloudTakesTheLeftGrey) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SgbmStereo stereo(smallConfig());
  stereo.setCalibration(msf::test::syntheticCalibration(kSize));
  stereo.setInputImages(pair.left, pair.right);
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  stereo.compute(cloud);
  for (int u : {10, 100, 200})
    EXPECT_EQ(cloud.at(u, 50).r, pair.left.at<std::uint8_t>(50, u));
}

TEST(SgbmStereo, ColourIsProjectedThroughTheColourCamera) {
  // A colour camera 0.1 m to the right of camera 0 sees a point at depth z shifted by
  // f * 0.1 / z pixels: the colour must come from there, not from the same pixel.
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::Calibration calibration = msf::test::syntheticCalibration(kSize, 500.0, 0.5);
  calibration.P[2](0, 3) = -500.0 * 0.1;
  cv::Mat color(kSize, CV_8UC3);
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < kSize.width; ++u)
      color.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<std::uint8_t>(u), 0, 0); // blue = column
  msf::SgbmStereo stereo(smallConfig());
  stereo.setCalibration(calibration);
  stereo.setInputImages(pair.left, pair.right);
  stereo.setInputColor(color);
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  stereo.compute(cloud);
  const auto& p = cloud.at(100, 80); // background, disparity 12, z = 20.8 m: shift 2.4 px
  ASSERT_TRUE(std::isfinite(p.z));
  const float expected_u = 100.f - 500.f * 0.1f / p.z;
  EXPECT_NEAR(p.b, std::lround(expected_u), 1.0);
}

TEST(SgbmStereo, ExplicitLeftRightCheckRemovesOcclusions) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SgbmConfig config = smallConfig();
  msf::SgbmStereo plain(config);
  plain.setInputImages(pair.left, pair.right);
  plain.computeDisparity();
  config.left_right_check = true;
  msf::SgbmStereo checked(config);
  checked.setInputImages(pair.left, pair.right);
  checked.computeDisparity();
  // Left of the square, 18 columns of background are hidden from the right camera.
  const cv::Rect occluded(pair.square.x - 16, pair.square.y + 4, 14, pair.square.height - 8);
  const auto bad = [&](const cv::Mat& d) {
    int n = 0;
    for (int v = occluded.y; v < occluded.y + occluded.height; ++v)
      for (int u = occluded.x; u < occluded.x + occluded.width; ++u)
        n += d.at<float>(v, u) > 0.f && std::fabs(d.at<float>(v, u) - 12.f) > 1.f;
    return n;
  };
  EXPECT_LE(bad(checked.getDisparity()), bad(plain.getDisparity()));
  EXPECT_LE(cv::countNonZero(checked.getDisparity() > 0.f), cv::countNonZero(plain.getDisparity() > 0.f));
  const cv::Rect inner(pair.square.x + 8, pair.square.y + 8, pair.square.width - 16, pair.square.height - 16);
  EXPECT_NEAR(medianIn(checked.getDisparity(), inner), 30.f, 0.1f);
}

TEST(SgbmStereo, DepthPriorNarrowsTheSearch) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  const msf::Calibration calibration = msf::test::syntheticCalibration(kSize, 500.0, 0.5);
  msf::SgbmConfig config;
  config.num_disparities_px = 128;
  msf::SgbmStereo stereo(config);
  stereo.setCalibration(calibration);
  stereo.setInputImages(pair.left, pair.right);
  cv::Mat prior(kSize, CV_32FC1, cv::Scalar(0));
  prior(pair.square).setTo(250.0 / 30.0); // nearest: disparity 30, + 8 margin -> 48
  stereo.setDepthPrior(prior);
  stereo.computeDisparity();
  EXPECT_EQ(stereo.getSearchedDisparities(), 48);
  const cv::Rect inner(pair.square.x + 8, pair.square.y + 8, pair.square.width - 16, pair.square.height - 16);
  EXPECT_NEAR(medianIn(stereo.getDisparity(), inner), 30.f, 0.1f);
  // Without the prior, the configured 128 disparities are searched.
  stereo.setDepthPrior(cv::Mat());
  stereo.computeDisparity();
  EXPECT_EQ(stereo.getSearchedDisparities(), 128);
  EXPECT_NEAR(medianIn(stereo.getDisparity(), inner), 30.f, 0.1f);
}

TEST(SearchRangeFromDepth, RoundsTheNearestDisparityPlusMarginUpTo16) {
  cv::Mat depth(10, 10, CV_32FC1, cv::Scalar(0));
  depth.at<float>(3, 3) = 2.f;  // f B = 100: disparity 50
  depth.at<float>(4, 4) = 10.f;
  EXPECT_EQ(msf::searchRangeFromDepth(depth, 100.0, 0, 8, 128), 64);  // 58 -> 64
  EXPECT_EQ(msf::searchRangeFromDepth(depth, 100.0, 0, 14, 128), 64); // 64 -> 64
  EXPECT_EQ(msf::searchRangeFromDepth(depth, 100.0, 0, 15, 128), 80); // 65 -> 80
  EXPECT_EQ(msf::searchRangeFromDepth(depth, 100.0, 0, 8, 48), 48);   // clamped
  EXPECT_EQ(msf::searchRangeFromDepth(cv::Mat(10, 10, CV_32FC1, cv::Scalar(0)), 100.0, 0, 8, 96), 96);
  EXPECT_THROW(msf::searchRangeFromDepth(cv::Mat(10, 10, CV_8UC1), 100.0, 0, 8, 96), msf::InvalidInputError);
  EXPECT_THROW(msf::searchRangeFromDepth(depth, 100.0, 0, 8, 100), msf::ConfigError);
}

TEST(StereoConfidence, HandMadeDisparity) {
  // 1 x 41 row: a hole at column 0, a flat run, then a 6 px step at column 30.
  cv::Mat d(1, 41, CV_32FC1, cv::Scalar(20.f));
  d.at<float>(0, 0) = 0.f;
  d.colRange(30, 41).setTo(26.f);
  msf::StereoConfidenceConfig config; // hole 15 px, window 5, free 1 px, scale 1 px
  const cv::Mat c = msf::stereoConfidence(d, config);
  EXPECT_EQ(c.at<float>(0, 0), 0.f);
  EXPECT_NEAR(c.at<float>(0, 1), 1.f - std::exp(-1.f / 15.f), 1e-5f);
  EXPECT_NEAR(c.at<float>(0, 20), 1.f - std::exp(-20.f / 15.f), 1e-5f);
  // Within 2 columns of the step, the local range is 6 px: 5 px over the free 1 px.
  EXPECT_NEAR(c.at<float>(0, 29), (1.f - std::exp(-29.f / 15.f)) * std::exp(-5.f), 1e-5f);
  EXPECT_NEAR(c.at<float>(0, 27), 1.f - std::exp(-27.f / 15.f), 1e-5f);
  // Hole distances beyond the hole term's table (1024 px).
  cv::Mat wide(1, 2100, CV_32FC1, cv::Scalar(20.f));
  wide.at<float>(0, 0) = 0.f;
  config.hole_distance_px = 1000.f;
  const cv::Mat cw = msf::stereoConfidence(wide, config);
  EXPECT_NEAR(cw.at<float>(0, 1000), 1.f - std::exp(-1.f), 1e-5f);
  EXPECT_NEAR(cw.at<float>(0, 1500), 1.f - std::exp(-1.5f), 1e-5f);
  config.range_window_px = 4;
  EXPECT_THROW(msf::stereoConfidence(d, config), msf::ConfigError);
  EXPECT_THROW(msf::stereoConfidence(cv::Mat(3, 3, CV_8UC1), {}), msf::InvalidInputError);
}

TEST(SgbmStereo, BadInputNamesWhatIsWrong) {
  const auto pair = msf::test::makeSyntheticPair(kSize, 12.f, 30.f);
  msf::SgbmStereo stereo(smallConfig());
  // A missing image.
  stereo.setInputImages(pair.left, cv::Mat());
  EXPECT_NE(msf::test::errorOf([&] { stereo.computeDisparity(); }).find("right image is missing"), std::string::npos);
  stereo.setInputImages(cv::Mat(), pair.right);
  EXPECT_THROW(stereo.computeDisparity(), msf::InvalidInputError);
  // Left and right of different sizes.
  stereo.setInputImages(pair.left, pair.right(cv::Rect(0, 0, 300, 160)));
  EXPECT_NE(msf::test::errorOf([&] { stereo.computeDisparity(); }).find("320x160 but the right image is 300x160"),
            std::string::npos);
  // Images whose size does not match the calibration.
  stereo.setCalibration(msf::test::syntheticCalibration(cv::Size(1226, 370)));
  stereo.setInputImages(pair.left, pair.right);
  EXPECT_NE(msf::test::errorOf([&] { stereo.computeDisparity(); }).find("320x160 but calibration 'synthetic' is 1226x370"),
            std::string::npos);
  // Not 8-bit.
  cv::Mat wide;
  pair.left.convertTo(wide, CV_16U);
  stereo.setCalibration(msf::test::syntheticCalibration(kSize));
  stereo.setInputImages(wide, wide);
  EXPECT_THROW(stereo.computeDisparity(), msf::InvalidInputError);
  // compute() needs a calibration.
  msf::SgbmStereo uncalibrated(smallConfig());
  uncalibrated.setInputImages(pair.left, pair.right);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  EXPECT_THROW(uncalibrated.compute(cloud), msf::CalibrationError);
  // A calibration without baseline.
  msf::Calibration flat = msf::test::syntheticCalibration(kSize);
  flat.P[1] = flat.P[0];
  EXPECT_THROW(stereo.setCalibration(flat), msf::CalibrationError);
}

TEST(SgbmConfig, ReadsTheStereoSectionAndRejectsBadValues) {
  msf::test::TempDir dir;
  const std::string path = dir.file("c.yaml");
  {
    std::ofstream out(path);
    out << "%YAML:1.0\nstereo:\n  engine: opencv\n  mode: hh\n  unguided_mode: sgbm\n  num_disparities_px: 64\n"
           "  block_size_px: 7\n  p1: 100\n  p2: 900\n  left_right_check: true\n  confidence_hole_distance_px: 9.5\n";
  }
  msf::SgbmConfig config;
  msf::ConfigFile(path).read(config);
  EXPECT_EQ(config.engine, "opencv");
  EXPECT_FALSE(config.nativeEngine());
  EXPECT_EQ(config.mode, "hh");
  EXPECT_EQ(config.unguided_mode, "sgbm");
  EXPECT_EQ(config.modeFor(true), "hh");
  EXPECT_EQ(config.modeFor(false), "sgbm");
  EXPECT_EQ(config.num_disparities_px, 64);
  EXPECT_EQ(config.block_size_px, 7);
  EXPECT_EQ(config.resolvedP1(), 100);
  EXPECT_EQ(config.resolvedP2(), 900);
  EXPECT_EQ(config.resolvedP1Rise(), 3 * 7 * 7);
  EXPECT_TRUE(config.left_right_check);
  EXPECT_FLOAT_EQ(config.confidence.hole_distance_px, 9.5f);
  EXPECT_EQ(config.uniqueness_ratio_pct, 10); // untouched default
  std::ostringstream printed;
  msf::printConfig(printed, config);
  EXPECT_NE(printed.str().find("num_disparities_px: 64"), std::string::npos);

  auto fails = [&](const std::string& body, const std::string& key) {
    std::ofstream(path) << "%YAML:1.0\nstereo:\n  " << body << "\n";
    msf::SgbmConfig c;
    try {
      msf::ConfigFile(path).read(c);
    } catch (const msf::ConfigError& e) {
      return std::string(e.what()).find(key) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(fails("num_disparities_px: 100", "stereo.num_disparities_px"));
  EXPECT_TRUE(fails("block_size_px: 4", "stereo.block_size_px"));
  EXPECT_TRUE(fails("mode: fast", "stereo.mode"));
  EXPECT_TRUE(fails("unguided_mode: ground", "stereo.unguided_mode"));
  EXPECT_TRUE(fails("p1_rise: -1", "stereo.p1_rise"));
  EXPECT_TRUE(fails("p1_rise: 800", "stereo.p1_rise")); // not below p2 (800 at block 5)
  EXPECT_TRUE(fails("engine: gpu", "stereo.engine"));
  EXPECT_TRUE(fails("p1: 500\n  p2: 400", "stereo.p2"));
  EXPECT_TRUE(fails("num_disparities_px: many", "stereo.num_disparities_px"));
  EXPECT_TRUE(fails("color_camera: 5", "stereo.color_camera"));
}

// ---- real KITTI ------------------------------------------------------------------------

/// Depth of the LiDAR returns projected into camera 0 (nearest wins): the reference.
cv::Mat lidarDepth(const std::string& scan, const msf::Calibration& c) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  msf::loadVelodyneBin(scan, cloud);
  cv::Mat depth(c.image_size, CV_32FC1, cv::Scalar(0));
  for (const auto& p : cloud) {
    const Eigen::Vector3d q = c.T_cam0_velo * Eigen::Vector3d(p.x, p.y, p.z);
    if (q.z() < 1.0)
      continue;
    const Eigen::Vector3d uvw = c.P[0] * q.homogeneous();
    const int u = static_cast<int>(std::lround(uvw.x() / uvw.z())), v = static_cast<int>(std::lround(uvw.y() / uvw.z()));
    if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows)
      continue;
    float& z = depth.at<float>(v, u);
    if (z == 0.f || q.z() < z)
      z = static_cast<float>(q.z());
  }
  return depth;
}

TEST(SgbmStereoKitti, OdometryFrameAgreesWithTheLidar) {
  MSF_REQUIRE_KITTI();
  const std::string seq = msf::test::kittiDir() + "/odometry/sequences/04/";
  const msf::Calibration calibration = msf::loadCalibration(seq + "calib.txt");
  msf::SgbmStereo stereo;
  stereo.setCalibration(calibration);
  stereo.setInputImages(msf::readImage(seq + "image_0/000000.png", cv::IMREAD_GRAYSCALE),
                        msf::readImage(seq + "image_1/000000.png", cv::IMREAD_GRAYSCALE));
  stereo.setInputColor(msf::readImage(seq + "image_2/000000.png", cv::IMREAD_COLOR));
  const cv::Mat lidar = lidarDepth(seq + "velodyne/000000.bin", calibration);
  stereo.setDepthPrior(lidar);
  pcl::PointCloud<PointXYZRGBConfidence> cloud;
  stereo.compute(cloud);
  EXPECT_EQ(cloud.width, 1226u);
  EXPECT_EQ(cloud.height, 370u);
  EXPECT_EQ(stereo.getSearchedDisparities(), 80); // nearest return ~5.8 m: disparity 65 + 8
  // D1 (3 px and 5 %) of the stereo disparity at the LiDAR pixels, and its coverage.
  const double fB = calibration.focalBaseline();
  int n = 0, estimated = 0, bad = 0, bad_confident = 0, confident = 0;
  for (int v = 0; v < lidar.rows; ++v)
    for (int u = 0; u < lidar.cols; ++u) {
      if (lidar.at<float>(v, u) <= 0.f)
        continue;
      ++n;
      const float d = stereo.getDisparity().at<float>(v, u);
      if (d <= 0.f)
        continue;
      ++estimated;
      const double d_gt = fB / lidar.at<float>(v, u), err = std::fabs(d - d_gt);
      const bool is_bad = err > 3.0 && err > 0.05 * d_gt;
      bad += is_bad;
      if (stereo.getConfidence().at<float>(v, u) > 0.5f) {
        ++confident;
        bad_confident += is_bad;
      }
      // The cloud holds the same depth.
      EXPECT_NEAR(cloud.at(u, v).z, fB / d, 1e-3 * fB / d);
    }
  ASSERT_GT(n, 10000);
  EXPECT_GT(static_cast<double>(estimated) / n, 0.9);
  EXPECT_LT(static_cast<double>(bad) / estimated, 0.06);
  // Confidence ranks the errors: confident pixels are bad far less often.
  EXPECT_LT(static_cast<double>(bad_confident) / confident, 0.5 * bad / estimated);
}

} // namespace
