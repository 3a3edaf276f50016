// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/reconstruction/scan_free_space.h>

#include <opencv2/imgproc.hpp>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_perpendicular_plane.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>

namespace msf {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kToDeg = 180.f / kPi;
constexpr int kColumns = static_cast<int>(360.f / ScanFreeSpace::kAzimuthBinDeg + 0.5f);
constexpr int kRows =
    static_cast<int>((ScanFreeSpace::kMaxElevationDeg - ScanFreeSpace::kMinElevationDeg) / ScanFreeSpace::kElevationBinDeg +
                     0.5f);

/// atan2 within 0.1 degree (a fifth of a bin), several times faster than std::atan2.
inline float fastAtan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float a = std::min(ax, ay) / std::max(std::max(ax, ay), 1e-30f);
  const float s = a * a;
  float r = ((-0.0464964749f * s + 0.15931422f) * s - 0.327622764f) * s * a + a;
  if (ay > ax)
    r = 0.5f * kPi - r;
  if (x < 0.f)
    r = kPi - r;
  return y < 0.f ? -r : r;
}

/// The bin of a direction, false outside the elevations kept.
inline bool binOf(float x, float y, float z, int& row, int& column) {
  const float azimuth = fastAtan2(y, x) * kToDeg + 180.f; // [0, 360]
  const float elevation = fastAtan2(z, std::sqrt(x * x + y * y)) * kToDeg;
  row = static_cast<int>((elevation - ScanFreeSpace::kMinElevationDeg) / ScanFreeSpace::kElevationBinDeg);
  column = static_cast<int>(azimuth / ScanFreeSpace::kAzimuthBinDeg) % kColumns;
  return elevation >= ScanFreeSpace::kMinElevationDeg && row < kRows;
}

/// The ground the scan stands on, as (n, d) with n the unit normal pointing up and n.p + d a
/// point's height over it: the largest plane within 20 degrees of level, 0.3 m or more under
/// the sensor, among every 16th return 2-20 m away across the ground (a plane needs no more).
/// None where it holds fewer than 100 of them or under a quarter: no ground in sight, or too
/// little to tell it from a plane that only cuts through what the sensor sees.
std::optional<Eigen::Vector4f> groundPlane(const pcl::PointCloud<pcl::PointXYZI>& scan) {
  constexpr float kMinHeightM = 0.3f, kNearM = 2.f, kFarM = 20.f, kInlierM = 0.1f;
  constexpr std::size_t kStride = 16, kMinInliers = 100;
  auto near = std::make_shared<pcl::PointCloud<pcl::PointXYZI>>();
  for (std::size_t i = 0; i < scan.size(); i += kStride) {
    const auto& p = scan[i];
    const float across2 = p.x * p.x + p.y * p.y;
    if (p.z < -kMinHeightM && across2 >= kNearM * kNearM && across2 <= kFarM * kFarM)
      near->push_back(p);
  }
  if (near->size() < kMinInliers)
    return std::nullopt;
  // Not random: PCL seeds the model's sampler with a constant, so a scan has one ground.
  auto model = std::make_shared<pcl::SampleConsensusModelPerpendicularPlane<pcl::PointXYZI>>(near);
  model->setAxis(Eigen::Vector3f::UnitZ());
  model->setEpsAngle(20.0 * M_PI / 180.0);
  pcl::RandomSampleConsensus<pcl::PointXYZI> ransac(model, kInlierM);
  if (!ransac.computeModel())
    return std::nullopt;
  pcl::Indices inliers;
  ransac.getInliers(inliers);
  if (inliers.size() < kMinInliers || inliers.size() < near->size() / 4)
    return std::nullopt;
  Eigen::VectorXf plane;
  ransac.getModelCoefficients(plane);
  Eigen::Vector4f up = plane.head<4>() / plane.head<3>().norm();
  if (up.z() < 0.f)
    up = -up;
  if (!(up.w() >= kMinHeightM)) // the sensor's own height over the plane
    return std::nullopt;
  return up;
}

} // namespace

ScanFreeSpace::ScanFreeSpace(const pcl::PointCloud<pcl::PointXYZI>& scan, bool swept)
    : skew_m_(swept ? kSweepSkewM : 0.f) {
  constexpr float kNone = std::numeric_limits<float>::infinity();
  cv::Mat nearest(kRows, kColumns, CV_32FC1, cv::Scalar(kNone));
  const std::optional<Eigen::Vector4f> ground = groundPlane(scan);
  for (const auto& p : scan) {
    const float range = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    int row, column;
    if (!(range > 1e-3f) || !std::isfinite(range) || !binOf(p.x, p.y, p.z, row, column))
      continue;
    float free_range = range;
    const float height = ground ? ground->dot(Eigen::Vector4f(p.x, p.y, p.z, 1.f)) : 0.f;
    if (height < -kBelowGroundM) { // the beam's free space ends where it met the ground
      const float sensor_height = ground->w();
      free_range = range * sensor_height / (sensor_height - height);
      ++below_ground_;
    }
    float& bin = nearest.at<float>(row, column);
    bin = std::min(bin, free_range);
  }
  // The minimum over each bin's 3 x 3 neighbourhood, azimuth wrapping round; empty bins hold
  // infinity, so they do not lower it, and give 0 where the bin itself is empty.
  cv::Mat wrapped;
  cv::copyMakeBorder(nearest, wrapped, 0, 0, 1, 1, cv::BORDER_WRAP);
  cv::Mat eroded;
  cv::erode(wrapped, eroded, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(kNone));
  nearest_ = eroded.colRange(1, kColumns + 1).clone();
  nearest_.setTo(0.f, nearest == kNone);
}

float ScanFreeSpace::nearestAround(const Eigen::Vector3f& p) const {
  int row, column;
  if (nearest_.empty() || !binOf(p.x(), p.y(), p.z(), row, column))
    return 0.f;
  return nearest_.at<float>(row, column);
}

} // namespace msf
