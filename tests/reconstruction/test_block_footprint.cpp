// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// BlockFootprint, the TSDF term of the memory prediction (Reconstructor::predictMemory): it holds
// every block the integrator really allocates, it is not far above a view's own volume, and
// 1000 frames take well under a second.
#include "test_support.h"

#include <msf/reconstruction/block_footprint.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <ctime>
#include <cmath>
#include <random>

using namespace msf;

namespace {

PinholeCamera pinhole(float f, float cx, float cy, int width, int height) {
  PinholeCamera camera;
  camera.fx = camera.fy = f;
  camera.cx = cx;
  camera.cy = cy;
  camera.width = width;
  camera.height = height;
  return camera;
}

/// KITTI odometry's camera 0, grown by `margin` pixels each side (the LiDAR canvas's 16).
PinholeCamera kittiCamera(int margin = 0) {
  return pinhole(718.856f, 607.19f + margin, 185.22f + margin, 1241 + 2 * margin, 376 + 2 * margin);
}

Eigen::Isometry3d randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), offset(-20.0, 20.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.3 * angle(rng), Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(0.1 * angle(rng), Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(offset(rng), 0.2 * offset(rng), offset(rng));
  return T;
}

TEST(BlockFootprint, HoldsEveryBlockTheIntegratorAllocates) {
  // Depth anywhere from min_depth_m to max_depth_m, and weights down to min_pixel_weight, whose
  // bands behind the surface are the widest (2 sigmas of 2 m): the integrator's worst case.
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config; // per-pixel weights, plane distance: the pipeline's
  config.max_depth_m = 12.0;
  config.allocation_stride = 1;
  TsdfIntegrator integrator(volume, config);
  const PinholeCamera camera = pinhole(40.f, 31.5f, 23.5f, 64, 48);
  BlockFootprint footprint(volume.voxelSize());
  std::mt19937 rng(19);
  std::uniform_real_distribution<float> depth(static_cast<float>(config.min_depth_m),
                                              static_cast<float>(config.max_depth_m));
  std::uniform_real_distribution<float> weight(config.min_pixel_weight, 100.f);
  for (int frame = 0; frame < 6; ++frame) {
    DepthFrame f;
    f.camera = camera;
    f.depth.create(camera.height, camera.width, CV_32FC1);
    f.weight.create(camera.height, camera.width, CV_32FC1);
    for (int v = 0; v < camera.height; ++v)
      for (int u = 0; u < camera.width; ++u) {
        // Smooth patches (the plane band needs neighbours) at random depths, the image's
        // corners at the largest depth.
        const bool corner = (u < 4 || u >= camera.width - 4) && (v < 4 || v >= camera.height - 4);
        f.depth.at<float>(v, u) = corner ? static_cast<float>(config.max_depth_m) : depth(rng);
        f.weight.at<float>(v, u) = corner || (u + v) % 5 == 0 ? config.min_pixel_weight : weight(rng);
      }
    cv::blur(f.depth, f.depth, cv::Size(3, 3));
    const Eigen::Isometry3d T = randomPose(rng);
    integrator.integrate(f, T);
    footprint.addView(camera, T, config.min_depth_m, integrator.allocationDepth());
  }
  ASSERT_GT(volume.numBlocks(), 500u);
  std::size_t outside = 0;
  for (const TsdfBlock* block : volume.blocks())
    outside += footprint.contains(block->index) ? 0 : 1;
  EXPECT_EQ(outside, 0u) << "of " << volume.numBlocks() << " blocks allocated, in a footprint of "
                         << footprint.blocks();
  EXPECT_GE(footprint.blocks(), volume.numBlocks());
}

TEST(BlockFootprint, IsAViewsVolumeInBlocksWithItsBorder) {
  // KITTI's camera to 44 m (max_depth_m 40 and the widest band): a frustum of 25 000 m^3, 49 000
  // blocks of 0.8 m; the blocks that meet its border add to that.
  const PinholeCamera kitti = kittiCamera();
  const double near = 0.1, far = 44.0, block = 0.8;
  const double w = kitti.width / kitti.fx * far, h = kitti.height / kitti.fy * far;
  const double frustum_blocks = w * h * far / 3.0 / (block * block * block);
  BlockFootprint footprint(0.1);
  footprint.addView(kitti, Eigen::Isometry3d::Identity(), near, far);
  EXPECT_GT(footprint.blocks(), frustum_blocks);
  EXPECT_LT(footprint.blocks(), 1.6 * frustum_blocks);
  // The same view again adds nothing; a rotated one at the same place adds its own.
  const std::size_t one = footprint.blocks();
  footprint.addView(kitti, Eigen::Isometry3d::Identity(), near, far);
  EXPECT_EQ(footprint.blocks(), one);
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  footprint.addView(kitti, turned, near, far);
  EXPECT_GT(footprint.blocks(), 19 * one / 10);
  EXPECT_LE(footprint.blocks(), 21 * one / 10); // its blocks lie on the same grid, differently cut
  // A ball: all of it, none of it, part of it.
  EXPECT_EQ(footprint.blocksWithin(Eigen::Vector3d::Zero(), 1000.0), footprint.blocks());
  EXPECT_EQ(footprint.blocksWithin(Eigen::Vector3d(0, 0, 500), 100.0), 0u);
  const std::size_t near_ball = footprint.blocksWithin(Eigen::Vector3d::Zero(), 10.0);
  EXPECT_GT(near_ball, 0u);
  EXPECT_LT(near_ball, footprint.blocks() / 10);
  EXPECT_TRUE(footprint.contains(Eigen::Vector3i(0, 0, 10)));
  EXPECT_FALSE(footprint.contains(Eigen::Vector3i(0, -40, 10)));
  EXPECT_NE(test::errorOf([&] { footprint.addView(kitti, Eigen::Isometry3d::Identity(), 5.0, 1.0); })
                .find("need 0 <= near < far"),
            std::string::npos);
}

TEST(BlockFootprint, AThousandFramesTakeWellUnderASecond) {
  // A KITTI drive: 1000 frames 1 m apart, turning slowly, 0.1 m voxels, views to 44 m.
  const PinholeCamera kitti = kittiCamera(16);
  BlockFootprint footprint(0.1);
  // CPU time, not wall time: the test runs beside others on a shared host.
  timespec start{}, end{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 1000; ++i) {
    footprint.addView(kitti, T, 0.1, 44.0);
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = Eigen::AngleAxisd(0.003, Eigen::Vector3d::UnitY()).toRotationMatrix();
    step.translation() = Eigen::Vector3d(0, 0, 1.0);
    T = T * step;
  }
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &end);
  const double ms = (end.tv_sec - start.tv_sec) * 1e3 + (end.tv_nsec - start.tv_nsec) * 1e-6;
  std::printf("1000 views: %zu blocks in %.0f ms of CPU\n", footprint.blocks(), ms);
  EXPECT_GT(footprint.blocks(), 1000000u);
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(ms, 5000.0) << "(under AddressSanitizer)";
#else
  EXPECT_LT(ms, 500.0);
#endif
}

} // namespace
