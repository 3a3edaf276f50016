// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/point_types.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace msf {

namespace {
/// A projection's buffers, one set per calling thread: the projector's const methods may run on
/// several threads at once, and each thread reuses its buffers from scan to scan.
struct ProjectionScratch {
  std::vector<int> pixel;   ///< per scan point: pixel index or -1
  std::vector<float> depth; ///< per scan point: depth in the camera
  cv::Mat winner;           ///< per pixel: the index of the winning return, -1 none
};

ProjectionScratch& projectionScratch() {
  thread_local ProjectionScratch scratch;
  return scratch;
}
} // namespace

void ProjectionConfig::validate() const {
  checkKeyRanges(*this);
  if (!(max_range_m > min_range_m))
    throw ConfigError("projection.max_range_m (" + configValue(max_range_m) +
                      ") must be greater than projection.min_range_m (" + configValue(min_range_m) + ")");
}

LidarProjector::LidarProjector(const Calibration& calibration, const ProjectionConfig& config) {
  config.validate();
  config_ = config;
  setCalibration(calibration);
}

void LidarProjector::setCalibration(const Calibration& calibration) {
  calibration.requireVelodyne();
  camera_ = PinholeCamera::fromCalibration(calibration, config_.camera);
  // P_i = K_i [I | t_i] on the rectified frame of camera 0, so the point in camera i's
  // frame is X_0 + K_i^-1 P_i.col(3) (a translation only: the cameras share one plane).
  const Eigen::Vector3d t_i = calibration.K(config_.camera).inverse() * calibration.P[config_.camera].col(3);
  T_camera_velo_ = calibration.T_cam0_velo;
  T_camera_velo_.translation() += t_i;
  T_cam_velo_ = T_camera_velo_.matrix().topRows<3>().cast<float>();
  skew_ = static_cast<float>(calibration.P[config_.camera](0, 1));
  calibration_ = calibration;
  calibrated_ = true;
}

void LidarProjector::setConfig(const ProjectionConfig& config) {
  config.validate();
  const bool camera_changed = config.camera != config_.camera;
  config_ = config;
  if (camera_changed && calibrated_)
    setCalibration(calibration_);
}

PinholeCamera LidarProjector::canvasCamera() const {
  const int m = config_.margin_px;
  return camera_.onCanvas(imageInCanvas(), {camera_.width + 2 * m, camera_.height + 2 * m});
}

cv::Rect LidarProjector::imageInCanvas() const {
  return {config_.margin_px, config_.margin_px, camera_.width, camera_.height};
}

void LidarProjector::scatter(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin, cv::Mat& depth,
                             cv::Mat* winner) const {
  if (!calibrated_)
    throw InvalidInputError("LidarProjector: no calibration set");
  const int W = camera_.width + 2 * margin, H = camera_.height + 2 * margin;
  const int n = static_cast<int>(scan.size());
  // This thread's buffers, bound here: the workers below write into them, not their own.
  std::vector<int>& pixel = projectionScratch().pixel;
  std::vector<float>& point_depth = projectionScratch().depth;
  pixel.resize(scan.size());
  point_depth.resize(scan.size());
  const Eigen::Matrix<float, 3, 4> T = T_cam_velo_;
  const float fx = camera_.fx, fy = camera_.fy, skew = skew_;
  const float cx = camera_.cx + static_cast<float>(margin), cy = camera_.cy + static_cast<float>(margin);
  const float r2min = config_.min_range_m * config_.min_range_m, r2max = config_.max_range_m * config_.max_range_m;
  const float umax = static_cast<float>(W) - 0.5f, vmax = static_cast<float>(H) - 0.5f;

  // Transform and project in parallel; the z-buffer below is serial over the points kept
  // (the quarter of the scan in front of the camera).
  parallelFor(cv::Range(0, n), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const pcl::PointXYZI& p = scan[static_cast<std::size_t>(i)];
      pixel[i] = -1;
      const float z = T(2, 0) * p.x + T(2, 1) * p.y + T(2, 2) * p.z + T(2, 3);
      if (!(z > 0.f))
        continue; // behind the camera (or NaN)
      const float r2 = p.x * p.x + p.y * p.y + p.z * p.z;
      if (r2 < r2min || r2 > r2max)
        continue;
      const float x = T(0, 0) * p.x + T(0, 1) * p.y + T(0, 2) * p.z + T(0, 3);
      const float y = T(1, 0) * p.x + T(1, 1) * p.y + T(1, 2) * p.z + T(1, 3);
      const float inv_z = 1.f / z;
      const float u = (fx * x + skew * y) * inv_z + cx;
      const float v = fy * y * inv_z + cy;
      if (!(u > -0.5f && u < umax && v > -0.5f && v < vmax))
        continue;
      // Pixel centres are integers (as in depthImageToCloud): round to nearest, u + 0.5 > 0.
      pixel[i] = static_cast<int>(v + 0.5f) * W + static_cast<int>(u + 0.5f);
      point_depth[i] = z;
    }
  });

  depth.create(H, W, CV_32FC1);
  depth.setTo(0.f);
  float* d = depth.ptr<float>();
  int* w = nullptr;
  if (winner) {
    winner->create(H, W, CV_32SC1);
    winner->setTo(-1);
    w = winner->ptr<int>();
  }
  for (int i = 0; i < n; ++i) {
    const int k = pixel[i];
    if (k < 0)
      continue;
    if (d[k] == 0.f || point_depth[i] < d[k]) {
      d[k] = point_depth[i];
      if (w)
        w[k] = i;
    }
  }
}

void LidarProjector::projectDepth(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin, cv::Mat& depth,
                                  cv::Mat* intensity) const {
  if (!intensity) {
    scatter(scan, margin, depth, nullptr);
    return;
  }
  cv::Mat& winner = projectionScratch().winner;
  scatter(scan, margin, depth, &winner);
  intensity->create(depth.size(), CV_32FC1);
  const int* w = winner.ptr<int>();
  float* out = intensity->ptr<float>();
  const int total = static_cast<int>(depth.total());
  parallelFor(cv::Range(0, total), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k)
      out[k] = w[k] >= 0 ? scan[static_cast<std::size_t>(w[k])].intensity : 0.f;
  });
}

void LidarProjector::projectToImage(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth,
                                    cv::Mat* intensity) const {
  projectDepth(scan, 0, depth, intensity);
}

void LidarProjector::projectToCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth,
                                     cv::Mat* intensity) const {
  projectDepth(scan, config_.margin_px, depth, intensity);
}

namespace {
template <typename PointT>
inline void setReflectance(PointT& p, float value) {
  if constexpr (pcl::traits::has_intensity_v<PointT>)
    p.intensity = value;
}
template <typename PointT>
inline void setDistance(PointT& p, float value) {
  if constexpr (std::is_same_v<PointT, PointXYZID>)
    p.distance = value;
}
} // namespace

template <typename PointT>
void LidarProjector::projectCloud(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin,
                                  pcl::PointCloud<PointT>& cloud) const {
  cv::Mat depth;
  cv::Mat& winner = projectionScratch().winner;
  scatter(scan, margin, depth, &winner);
  const int W = depth.cols, H = depth.rows;
  cloud.resize(static_cast<std::size_t>(W) * H);
  cloud.width = static_cast<std::uint32_t>(W);
  cloud.height = static_cast<std::uint32_t>(H);
  cloud.header = scan.header; // the scan's stamp, in the camera's frame
  cloud.header.frame_id = cameraFrameId(config_.camera);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const Eigen::Matrix<float, 3, 4> T = T_cam_velo_;
  const int* w = winner.ptr<int>();
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, W * H), [&](const cv::Range& range) {
    bool all = true;
    for (int k = range.start; k < range.end; ++k) {
      PointT& out = cloud[static_cast<std::size_t>(k)];
      if (w[k] < 0) {
        out.x = out.y = out.z = nan;
        setReflectance(out, 0.f);
        setDistance(out, inf);
        all = false;
        continue;
      }
      const pcl::PointXYZI& p = scan[static_cast<std::size_t>(w[k])];
      out.x = T(0, 0) * p.x + T(0, 1) * p.y + T(0, 2) * p.z + T(0, 3);
      out.y = T(1, 0) * p.x + T(1, 1) * p.y + T(1, 2) * p.z + T(1, 3);
      out.z = depth.ptr<float>()[k]; // the same float as the z-buffer
      setReflectance(out, p.intensity);
      setDistance(out, 0.f);
    }
    if (!all)
      dense = false;
  });
  cloud.is_dense = dense;
}

template <typename PointT>
void LidarProjector::project(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointT>& cloud) const {
  projectCloud(scan, 0, cloud);
}

template <typename PointT>
void LidarProjector::projectCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointT>& cloud) const {
  projectCloud(scan, config_.margin_px, cloud);
}

#define MSF_INSTANTIATE_PROJECTOR(T)                                                                    \
  template void LidarProjector::project<T>(const pcl::PointCloud<pcl::PointXYZI>&, pcl::PointCloud<T>&) const; \
  template void LidarProjector::projectCanvas<T>(const pcl::PointCloud<pcl::PointXYZI>&, pcl::PointCloud<T>&) const;
MSF_INSTANTIATE_PROJECTOR(pcl::PointXYZ)
MSF_INSTANTIATE_PROJECTOR(pcl::PointXYZI)
MSF_INSTANTIATE_PROJECTOR(PointXYZID)

} // namespace msf
