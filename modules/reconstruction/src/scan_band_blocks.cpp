// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/reconstruction/scan_band_blocks.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace msf {

namespace {
constexpr int kSide = TsdfBlock::kSide;
} // namespace

ScanBandBlocks::ScanBandBlocks(double voxel_size_m, double band_m, double near_m, double far_m)
    : voxel_size_(voxel_size_m), band_(band_m), near_(near_m), far_(far_m) {
  if (!(voxel_size_m > 0.0) || !std::isfinite(voxel_size_m))
    throw InvalidInputError("ScanBandBlocks: the voxel size must be > 0, got " + std::to_string(voxel_size_m));
  if (!(band_m >= 0.0 && std::isfinite(band_m) && near_m >= 0.0 && far_m > near_m && std::isfinite(far_m)))
    throw InvalidInputError("ScanBandBlocks: need a band >= 0 and 0 <= near < far, finite; got " +
                            std::to_string(band_m) + ", " + std::to_string(near_m) + ", " + std::to_string(far_m));
}

GridIndex ScanBandBlocks::blockOf(const Eigen::Vector3d& p) const {
  // As the integrator's sub-block keys: block floor((p / vs + 1/2) / kSide).
  const Eigen::Vector3d b = ((p / voxel_size_).array() + 0.5) / kSide;
  return b.array().floor().cast<int>();
}

void ScanBandBlocks::addScan(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_cam_lidar,
                             const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam) {
  if (!camera.valid())
    throw InvalidInputError("ScanBandBlocks::addScan: the camera is not valid (fx, fy > 0, a size)");
  const Eigen::Isometry3d T_world_lidar = T_world_cam * T_cam_lidar;
  const Eigen::Vector3d origin = T_world_cam.translation();
  // Samples along the band no farther apart than half a block, so that no block it crosses is missed.
  const double block_m = kSide * voxel_size_;
  const int steps = static_cast<int>(std::ceil(2.0 * band_ / (0.5 * block_m)));
  for (const pcl::PointXYZI& q : scan.points) {
    const Eigen::Vector3d p_lidar(q.x, q.y, q.z);
    const Eigen::Vector3d p_cam = T_cam_lidar * p_lidar;
    if (!(p_cam.z() >= near_ && p_cam.z() <= far_))
      continue;
    const double u = camera.fx * p_cam.x() / p_cam.z() + camera.cx, v = camera.fy * p_cam.y() / p_cam.z() + camera.cy;
    if (!(u >= -0.5 && v >= -0.5 && u < camera.width - 0.5 && v < camera.height - 0.5))
      continue;
    const Eigen::Vector3d p = T_world_lidar * p_lidar;
    const Eigen::Vector3d ray = (p - origin).normalized();
    for (int s = 0; s <= steps; ++s)
      blocks_.insert(blockOf(p + ray * (steps ? band_ * (2.0 * s / steps - 1.0) : 0.0)));
  }
}

std::size_t ScanBandBlocks::blocksWithin(const Eigen::Vector3d& centre, double radius_m) const {
  const double half = 0.5 * kSide * voxel_size_;
  std::size_t n = 0;
  for (const GridIndex& b : blocks_) {
    // The block's box centre, and how far the ball's centre is outside it along each axis.
    const Eigen::Vector3d c = ((b.cast<double>() * kSide).array() + 0.5 * kSide - 0.5) * voxel_size_;
    const Eigen::Vector3d gap = ((c - centre).cwiseAbs().array() - half).max(0.0);
    n += gap.squaredNorm() <= radius_m * radius_m;
  }
  return n;
}

} // namespace msf
