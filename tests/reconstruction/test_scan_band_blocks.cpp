// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// ScanBandBlocks, the surfaces of the memory prediction (Reconstructor::predictMemory): the blocks
// within the band of the returns a camera sees, their union over scans, and those near a point.
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/scan_band_blocks.h>

using namespace msf;

namespace {

/// A 100x100 camera of 90 degrees' view.
PinholeCamera squareCamera() {
  PinholeCamera camera;
  camera.fx = camera.fy = 50.0;
  camera.cx = camera.cy = 49.5;
  camera.width = camera.height = 100;
  return camera;
}

pcl::PointCloud<pcl::PointXYZI> scanOf(std::initializer_list<Eigen::Vector3f> points) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (const Eigen::Vector3f& p : points) {
    pcl::PointXYZI q;
    q.x = p.x();
    q.y = p.y();
    q.z = p.z();
    q.intensity = 0.f;
    scan.push_back(q);
  }
  return scan;
}

const Eigen::Isometry3d kIdentity = Eigen::Isometry3d::Identity();

} // namespace

TEST(ScanBandBlocks, CountsOnlyTheReturnsTheCameraSeesWithinItsDepths) {
  // 0.1 m voxels: blocks of 0.8 m; no band: the block of each return.
  ScanBandBlocks bands(0.1, 0.0, 0.5, 60.0);
  bands.addScan(scanOf({{0.f, 0.f, 10.f},     // seen
                        {0.1f, 0.1f, 10.1f},  // seen, the same block
                        {0.f, 0.f, 100.f},    // beyond 60 m
                        {0.f, 0.f, 0.2f},     // nearer than 0.5 m
                        {0.f, 0.f, -5.f},     // behind the camera
                        {30.f, 0.f, 10.f}}),  // outside the image (x / z = 3 > 1)
                kIdentity, squareCamera(), kIdentity);
  EXPECT_EQ(bands.blocks(), 1u);
}

TEST(ScanBandBlocks, TheBandAddsEveryBlockAlongTheRay) {
  // A return at 10 m with a band of 0.5 m: voxel coordinates 95.5 .. 105.5, blocks 11, 12, 13.
  ScanBandBlocks bands(0.1, 0.5, 0.5, 60.0);
  bands.addScan(scanOf({{0.f, 0.f, 10.f}}), kIdentity, squareCamera(), kIdentity);
  EXPECT_EQ(bands.blocks(), 3u);
}

TEST(ScanBandBlocks, IsTheUnionOverScansPlacedByTheirPoses) {
  ScanBandBlocks bands(0.1, 0.0, 0.5, 60.0);
  const auto scan = scanOf({{0.f, 0.f, 10.f}, {-3.f, 0.f, 10.f}});
  bands.addScan(scan, kIdentity, squareCamera(), kIdentity);
  ASSERT_EQ(bands.blocks(), 2u);
  bands.addScan(scan, kIdentity, squareCamera(), kIdentity);
  EXPECT_EQ(bands.blocks(), 2u) << "the same surface seen again adds nothing";
  Eigen::Isometry3d moved = kIdentity;
  moved.translation() = Eigen::Vector3d(20.0, 0.0, 0.0);
  bands.addScan(scan, kIdentity, squareCamera(), moved);
  EXPECT_EQ(bands.blocks(), 4u) << "the same scan 20 m away";
  // The LiDAR's extrinsic places the returns in the camera: 100 m ahead is beyond 60 m.
  Eigen::Isometry3d far_ahead = kIdentity;
  far_ahead.translation() = Eigen::Vector3d(0.0, 0.0, 90.0);
  bands.addScan(scan, far_ahead, squareCamera(), kIdentity);
  EXPECT_EQ(bands.blocks(), 4u);
}

TEST(ScanBandBlocks, BlocksWithinABall) {
  ScanBandBlocks bands(0.1, 0.0, 0.5, 60.0);
  Eigen::Isometry3d moved = kIdentity;
  moved.translation() = Eigen::Vector3d(20.0, 0.0, 0.0);
  const auto scan = scanOf({{0.f, 0.f, 10.f}});
  bands.addScan(scan, kIdentity, squareCamera(), kIdentity);
  bands.addScan(scan, kIdentity, squareCamera(), moved);
  EXPECT_EQ(bands.blocksWithin(Eigen::Vector3d(0.0, 0.0, 10.0), 1.0), 1u);
  EXPECT_EQ(bands.blocksWithin(Eigen::Vector3d(10.0, 0.0, 10.0), 11.0), 2u);
  EXPECT_EQ(bands.blocksWithin(Eigen::Vector3d(10.0, 0.0, 10.0), 5.0), 0u);
}

TEST(ScanBandBlocks, BadArgumentsAreNamed) {
  EXPECT_THROW(ScanBandBlocks(0.0, 0.3, 0.5, 60.0), InvalidInputError);
  EXPECT_THROW(ScanBandBlocks(0.1, -1.0, 0.5, 60.0), InvalidInputError);
  EXPECT_THROW(ScanBandBlocks(0.1, 0.3, 60.0, 0.5), InvalidInputError);
  ScanBandBlocks bands(0.1, 0.3, 0.5, 60.0);
  EXPECT_THROW(bands.addScan(scanOf({}), kIdentity, PinholeCamera(), kIdentity), InvalidInputError);
}
