// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The generator checks itself: LiDAR against the depth ground truth, SGBM on the rendered
// pair against the disparity ground truth, the ring structure of the scans.
#include "synthetic_fixture.h"

#include <msf/common/statistics.h>
#include <msf/io/organized_conversion.h>
#include <msf/range_image/ring_split.h>
#include <msf/synthetic/kitti_rig.h>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>

namespace {

using msf::test::SharedStreet;

/// |z_lidar - z_gt| of every LiDAR point that projects into camera 0, with the ground-truth
/// depth interpolated bilinearly in inverse depth (exact on planes) where the four
/// neighbouring pixels agree within 5 %.
std::vector<double> lidarDepthErrors(const pcl::PointCloud<pcl::PointXYZI>& scan, const cv::Mat& gt_depth,
                                     const msf::Calibration& calib) {
  std::vector<double> errors;
  const Eigen::Matrix<double, 3, 4> P = calib.P[0];
  for (const auto& p : scan) {
    const Eigen::Vector3d c = calib.T_cam0_velo * Eigen::Vector3d(p.x, p.y, p.z);
    if (c.z() < 1.0)
      continue;
    const Eigen::Vector3d uvw = P * c.homogeneous();
    const double u = uvw.x() / uvw.z(), v = uvw.y() / uvw.z();
    const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
    if (u0 < 0 || v0 < 0 || u0 + 1 >= gt_depth.cols || v0 + 1 >= gt_depth.rows)
      continue;
    const float z00 = gt_depth.at<float>(v0, u0), z10 = gt_depth.at<float>(v0, u0 + 1);
    const float z01 = gt_depth.at<float>(v0 + 1, u0), z11 = gt_depth.at<float>(v0 + 1, u0 + 1);
    const float lo = std::min({z00, z10, z01, z11}), hi = std::max({z00, z10, z01, z11});
    if (lo <= 0.f || hi > 1.05f * lo)
      continue; // sky or a depth edge: no single surface under the point
    const double a = u - u0, b = v - v0;
    const double inv = (1 - a) * (1 - b) / z00 + a * (1 - b) / z10 + (1 - a) * b / z01 + a * b / z11;
    errors.push_back(std::fabs(c.z() - 1.0 / inv));
  }
  return errors;
}

TEST(SyntheticSensors, LidarMatchesDepthGroundTruthWithinNoise) {
  auto& street = SharedStreet::instance();
  const auto& gen = street.generator();
  double worst = 0.0;
  for (std::size_t i : {0u, 5u}) {
    const auto& f = street.frame(i);
    const auto errors = lidarDepthErrors(f.scan, f.depth, gen.calibration());
    ASSERT_GT(errors.size(), 10000u) << "frame " << i << ": too few LiDAR points in camera 0";
    const double med = msf::median(errors);
    std::printf("frame %zu: %zu LiDAR points in camera 0, median |dz| = %.4f m (range noise sigma %.3f m)\n", i,
                errors.size(), med, gen.config().lidar_range_noise_m);
    worst = std::max(worst, med);
  }
  // The median of |N(0, s)| is 0.674 s; the issue allows 3 cm beyond the configured noise.
  EXPECT_LE(worst, gen.config().lidar_range_noise_m + 0.03);
}

TEST(SyntheticSensors, NoiselessLidarHitsTheSurfaceExactly) {
  auto config = SharedStreet::config();
  config.lidar_range_noise_m = 0.0;
  config.lidar_dropout = 0.0;
  const msf::synthetic::SyntheticGenerator gen(config);
  const Eigen::Isometry3d& T = gen.poses()[3];
  const auto scan = gen.lidar().scan(gen.sceneAt(3), T * gen.calibration().T_cam0_velo, 3);
  const msf::synthetic::CameraRenderer renderer(gen.calibration(), config);
  cv::Mat depth, objects;
  renderer.render(gen.sceneAt(3), 0, T, 3, &depth, &objects);
  const auto errors = lidarDepthErrors(scan, depth, gen.calibration());
  ASSERT_GT(errors.size(), 10000u);
  const double med = msf::median(errors);
  std::printf("noiseless LiDAR: median |dz| = %.5f m over %zu points\n", med, errors.size());
  EXPECT_LT(med, 0.005);
}

TEST(SyntheticSensors, ScanHas64RingsOfOneSweepEach) {
  auto& street = SharedStreet::instance();
  const auto& gen = street.generator();
  const auto scan = street.scan(0);
  pcl::PointCloud<pcl::PointXYZI> input, heldout;
  const int rings = msf::splitRings(scan, msf::RingSplitConfig(), input, heldout);
  EXPECT_EQ(rings, 64);
  EXPECT_EQ(input.size() + heldout.size(), scan.size());
  // Held out: ids 2, 6, ..., 62, a quarter of the rings.
  EXPECT_NEAR(static_cast<double>(heldout.size()) / scan.size(), 0.25, 0.06);

  // The protocol's definition directly: a ring changes where atan2(y, x) drops by more than
  // pi; within a ring the azimuth only rises; elevations follow the lasers, top first.
  const std::vector<int> ids = msf::ringIds(scan);
  const auto& elevations = gen.lidar().elevationsDeg();
  ASSERT_EQ(elevations.size(), 64u);
  EXPECT_DOUBLE_EQ(elevations.front(), 2.0);
  EXPECT_DOUBLE_EQ(elevations.back(), -24.9);
  std::vector<std::size_t> per_ring(64, 0);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const auto& p = scan[i];
    ASSERT_LT(ids[i], 64);
    ++per_ring[static_cast<std::size_t>(ids[i])];
    if (i > 0 && ids[i] == ids[i - 1]) {
      ASSERT_GE(std::atan2(p.y, p.x), std::atan2(scan[i - 1].y, scan[i - 1].x)) << "point " << i;
    }
    // The velodyne is nearly level: the point's elevation is its laser's (noise moves
    // points along the beam only).
    const double elevation = std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI;
    ASSERT_NEAR(elevation, elevations[static_cast<std::size_t>(ids[i])], 1e-3) << "point " << i;
    const double range = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    ASSERT_LE(range, gen.config().lidar_max_range_m + 0.2);
    ASSERT_GE(p.intensity, 0.f);
    ASSERT_LE(p.intensity, 1.f);
  }
  for (std::size_t r = 0; r < 64; ++r)
    EXPECT_GT(per_ring[r], 200u) << "ring " << r;
  // KITTI-like density: ~2000 azimuth steps a ring, about 120k points a scan.
  EXPECT_EQ(gen.lidar().pointsPerRing(), 2000);
  EXPECT_GT(scan.size(), 90000u);
  EXPECT_LT(scan.size(), 128000u);
}

/// D1 (3 px and 5 %) of `estimate` over the pixels with ground truth and an estimate.
struct D1 {
  std::size_t gt = 0, estimated = 0, bad = 0;
  double onEstimates() const { return estimated ? static_cast<double>(bad) / estimated : 1.0; }
  double coverage() const { return gt ? static_cast<double>(estimated) / gt : 0.0; }
};

D1 evaluate(const cv::Mat& gt, const cv::Mat& estimate) {
  D1 r;
  for (int v = 0; v < gt.rows; ++v)
    for (int u = 0; u < gt.cols; ++u) {
      const float g = gt.at<float>(v, u), e = estimate.at<float>(v, u);
      if (g <= 0.f)
        continue;
      ++r.gt;
      if (e <= 0.f)
        continue;
      ++r.estimated;
      const float err = std::fabs(e - g);
      r.bad += (err > 3.f && err > 0.05f * g) ? 1 : 0;
    }
  return r;
}

TEST(SyntheticSensors, SgbmOnTheRenderedPairAgreesWithDisparityGroundTruth) {
  auto& street = SharedStreet::instance();
  // OpenCV SGBM 3-way, 128 disparities, 5x5 blocks: the project's baseline setting.
  auto sgbm = cv::StereoSGBM::create(0, 128, 5, 8 * 25, 32 * 25, -1, 63, 10, 100, 2, cv::StereoSGBM::MODE_SGBM_3WAY);
  for (std::size_t i : {0u, 5u}) {
    const auto& f = street.frame(i);
    cv::Mat raw, disparity;
    sgbm->compute(f.images[0], f.images[1], raw);
    raw.convertTo(disparity, CV_32F, 1.0 / 16.0);
    // Left of column 128 the search range leaves the image: no estimate there by design.
    const D1 all = evaluate(f.disparity, disparity);
    const cv::Rect matchable(128, 0, f.disparity.cols - 128, f.disparity.rows);
    const D1 inner = evaluate(f.disparity(matchable), disparity(matchable));
    std::printf("frame %zu: SGBM D1 on estimates %.2f %% (coverage %.3f); right of column 128: D1 %.2f %%, coverage "
                "%.3f\n",
                i, 100 * all.onEstimates(), all.coverage(), 100 * inner.onEstimates(), inner.coverage());
    EXPECT_LE(all.onEstimates(), 0.15) << "frame " << i;
    EXPECT_GT(inner.coverage(), 0.6) << "frame " << i;
  }
}

TEST(SyntheticSensors, DepthGroundTruthOfTheRoadIsExact) {
  auto& street = SharedStreet::instance();
  const auto& gen = street.generator();
  const auto& calib = gen.calibration();
  msf::synthetic::SyntheticFrame f;
  cv::Mat ids;
  // The static street: the cars driving ahead in the ego lane are left out.
  msf::synthetic::Scene static_street = gen.scene();
  static_street.movers.clear();
  msf::synthetic::CameraRenderer(calib, gen.config())
      .render(msf::synthetic::SceneSnapshot(static_street, 0.0), 0, gen.poses()[0], 0, &f.depth, &ids);
  ids.convertTo(f.objects, CV_8U); // saturating: only zero or not matters here
  f.disparity = msf::depthToDisparity(f.depth, calib);
  // Frame 0 is the world origin: the road plane is y = 1.65 m, so below the horizon a road
  // pixel (u, v) sees depth f h / (v - cy). The ego lane is free of objects ahead.
  for (int v : {300, 340, 374}) {
    const double expected = calib.fy() * msf::synthetic::kCameraHeightM / (v - calib.cy());
    EXPECT_NEAR(f.depth.at<float>(v, 621), expected, 1e-4 * expected) << "row " << v;
    EXPECT_EQ(f.objects.at<std::uint8_t>(v, 621), 0);
    EXPECT_NEAR(f.disparity.at<float>(v, 621), calib.focalBaseline() / expected, 1e-4) << "row " << v;
  }
  // The sky (top rows between the façades) has no ground truth.
  EXPECT_EQ(f.depth.at<float>(0, 621), 0.f);
  EXPECT_EQ(f.disparity.at<float>(0, 621), 0.f);
  // Foreground exists and carries ground truth.
  EXPECT_GT(cv::countNonZero(f.objects), 5000);
  EXPECT_EQ(cv::countNonZero(f.objects & (f.depth == 0.f)), 0);
}

} // namespace
