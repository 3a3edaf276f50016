// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Volume sizes, sweeps, poses and memory that would run away end in an error
// naming the key or option, before the volume allocates.
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <opencv2/core.hpp>

namespace {

using msf::test::errorOf;

msf::DepthFrame wall(float z = 5.f) {
  msf::DepthFrame frame;
  frame.camera.fx = frame.camera.fy = 60.f;
  frame.camera.cx = 31.5f;
  frame.camera.cy = 23.5f;
  frame.camera.width = 64;
  frame.camera.height = 48;
  frame.depth = cv::Mat(48, 64, CV_32FC1, cv::Scalar(z));
  return frame;
}

TEST(VolumeLimits, VoxelAndTruncationRanges) {
  EXPECT_NE(errorOf([] { msf::TsdfVolume(1e-6, 0.3); }).find("voxel_size_m (-voxel, the voxel size) must be 0.001 .. 10 m, got 1e-06"),
            std::string::npos);
  EXPECT_NE(errorOf([] { msf::TsdfVolume(1e6, 0.3); }).find("got 1000000"), std::string::npos);
  EXPECT_NE(errorOf([] { msf::TsdfVolume(0.1, 1e6); }).find("truncation_m (-trunc) must be > 0 and at most 64 voxels"),
            std::string::npos);
  EXPECT_NO_THROW(msf::TsdfVolume(0.1, 0.3));
  EXPECT_NO_THROW(msf::TsdfVolume(0.001, 0.064));
}

TEST(VolumeLimits, SweepsAndDepthRange) {
  msf::TsdfIntegrator::Config c;
  c.sweeps = 1000000;
  EXPECT_NE(errorOf([&] { c.validate(); }).find("tsdf_integrator.sweeps must be in 0..100, not 1000000"), std::string::npos);
  c.sweeps = 1;
  c.max_depth_m = 1e30;
  const std::string depth_error = errorOf([&] { c.validate(); });
  EXPECT_NE(depth_error.find("tsdf_integrator.max_depth_m must be in"), std::string::npos) << depth_error;
  EXPECT_NE(depth_error.find("1000]"), std::string::npos) << depth_error;
}

TEST(VolumeLimits, MemoryBudgetStopsTheRunBeforeItAllocates) {
  msf::TsdfVolume volume(0.001, 0.05);
  volume.setMaxMemoryMb(8);
  msf::TsdfIntegrator integrator(volume);
  const std::string e = errorOf([&] { integrator.integrate(wall(), Eigen::Isometry3d::Identity()); });
  EXPECT_NE(e.find("over its memory budget of 8 MiB (tsdf_volume.max_memory_mb, -max_memory)"), std::string::npos) << e;
  EXPECT_LE(volume.memoryBytes(), std::size_t(8) << 20);
  // The same frame at 0.1 m voxels fits.
  msf::TsdfVolume coarse(0.1, 0.3);
  coarse.setMaxMemoryMb(8);
  msf::TsdfIntegrator fits(coarse);
  EXPECT_NO_THROW(fits.integrate(wall(), Eigen::Isometry3d::Identity()));
}

TEST(VolumeLimits, PosesThatAreNotRigidOrOutOfReach) {
  msf::TsdfVolume volume(0.001, 0.003);
  msf::TsdfIntegrator integrator(volume);
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 1000.0;
  EXPECT_NE(errorOf([&] { integrator.integrate(wall(), scaled); }).find("is not a rigid transform"), std::string::npos);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation().x() = 2.5e30; // converted to int: undefined behaviour
  EXPECT_NE(errorOf([&] { integrator.integrate(wall(), far); }).find("translation of 2.5e+30 m"), std::string::npos);
  // Within the pose limits but beyond what 20-bit block keys hold at 1 mm voxels (4.2 km).
  Eigen::Isometry3d beyond = Eigen::Isometry3d::Identity();
  beyond.translation().x() = 9e5;
  EXPECT_NE(errorOf([&] { integrator.integrate(wall(), beyond); }).find("beyond the volume's"), std::string::npos);
  EXPECT_EQ(volume.numBlocks(), 0u);
}

} // namespace
