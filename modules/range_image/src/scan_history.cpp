// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/range_image/scan_history.h>

#include <pcl/common/transforms.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace msf {

void ScanHistoryConfig::validate() const { checkKeyRanges(*this); }

ScanHistory::ScanHistory(const Calibration& calibration, const ProjectionConfig& projection,
                         const ScanHistoryConfig& config)
    : config_(config), projector_(calibration, projection) {
  config_.validate();
  T_velo_cam_ = projector_.cameraFromLidar().inverse();
}

const pcl::PointCloud<pcl::PointXYZI>& ScanHistory::withEarlierScans(const pcl::PointCloud<pcl::PointXYZI>& scan,
                                                                      const Eigen::Isometry3d* T_world_velo) {
  if (config_.scans == 0)
    return scan;
  if (!T_world_velo) {
    clear(); // earlier scans cannot be placed without the poses
    return scan;
  }
  densify(scan, *T_world_velo, dense_);
  return dense_;
}

void ScanHistory::densify(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_velo,
                          pcl::PointCloud<pcl::PointXYZI>& out) {
  stats_ = Stats();
  out = scan;
  if (!scans_.empty()) {
    projector_.projectToCanvas(scan, current_);
    added_.create(current_.size(), CV_32FC1);
    added_.setTo(0.f);
    const Eigen::Isometry3d T_velo_world = T_world_velo.inverse();
    for (std::size_t i = 0; i < scans_.size(); ++i) // newest first: a pixel keeps its newest return
      addAgreeing(scans_[i], static_cast<int>(i) + 1, T_velo_world, out);
    out.width = static_cast<std::uint32_t>(out.size());
    out.height = 1;
  }
  remember(scan, T_world_velo);
}

void ScanHistory::addAgreeing(const Entry& earlier, int age, const Eigen::Isometry3d& T_velo_world,
                              pcl::PointCloud<pcl::PointXYZI>& out) {
  const Eigen::Isometry3d T_current_earlier = T_velo_world * earlier.T_world_velo;
  pcl::transformPointCloud(*earlier.points, moved_, T_current_earlier.matrix().cast<float>());
  projector_.projectCanvas(moved_, organized_);
  const float age_sigma_m = static_cast<float>(age) * config_.translation_sigma_m;
  const float age_sigma_rad = static_cast<float>(age) * config_.rotation_sigma_deg * static_cast<float>(M_PI / 180.0);
  const Eigen::Affine3f T_velo_cam = T_velo_cam_.cast<float>();
  const int w = current_.cols, h = current_.rows;
  for (int v = 0; v < h; ++v) {
    const float* cur_above = current_.ptr<float>(std::max(v - 1, 0));
    const float* cur = current_.ptr<float>(v);
    const float* cur_below = current_.ptr<float>(std::min(v + 1, h - 1));
    float* added = added_.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const pcl::PointXYZI& p = organized_(static_cast<std::uint32_t>(u), static_cast<std::uint32_t>(v));
      if (!std::isfinite(p.z) || added[u] > 0.f)
        continue;
      ++stats_.earlier_in_view;
      bool near_current = false;
      for (int du = std::max(u - 1, 0); du <= std::min(u + 1, w - 1); ++du)
        near_current = near_current || cur_above[du] > 0.f || cur[du] > 0.f || cur_below[du] > 0.f;
      if (near_current) {
        ++stats_.on_current;
        continue;
      }
      float nearest = 0.f, farthest = 0.f;
      if (!bracket(u, v, nearest, farthest)) {
        ++stats_.unbracketed;
        continue;
      }
      const float depth = p.z;
      const float pose_sigma = std::hypot(age_sigma_m, age_sigma_rad * depth);
      const float tolerance = config_.agreement_m + config_.agreement_rel * depth + 3.f * pose_sigma;
      if (depth < nearest - tolerance || depth > farthest + tolerance) {
        ++stats_.disagreeing;
        continue;
      }
      added[u] = depth;
      pcl::PointXYZI q;
      q.getVector3fMap() = T_velo_cam * p.getVector3fMap();
      q.intensity = p.intensity;
      out.push_back(q);
      ++stats_.added;
    }
  }
}

bool ScanHistory::bracket(int u, int v, float& nearest, float& farthest) const {
  const int u0 = std::max(u - config_.window_cols_px, 0);
  const int u1 = std::min(u + config_.window_cols_px, current_.cols - 1);
  nearest = std::numeric_limits<float>::max();
  farthest = 0.f;
  // The first row on each side with a return in the window: the current ring there.
  auto nearestRow = [&](int step) {
    for (int r = v + step, n = 0; n < config_.window_rows_px && r >= 0 && r < current_.rows; r += step, ++n) {
      const float* row = current_.ptr<float>(r);
      bool found = false;
      for (int c = u0; c <= u1; ++c)
        if (row[c] > 0.f) {
          nearest = std::min(nearest, row[c]);
          farthest = std::max(farthest, row[c]);
          found = true;
        }
      if (found)
        return true;
    }
    return false;
  };
  return nearestRow(-1) && nearestRow(+1);
}

void ScanHistory::remember(const pcl::PointCloud<pcl::PointXYZI>& scan, const Eigen::Isometry3d& T_world_velo) {
  if (config_.scans == 0)
    return;
  Entry entry;
  if (static_cast<int>(scans_.size()) == config_.scans) { // reuse the oldest's memory
    entry = std::move(scans_.back());
    scans_.pop_back();
  } else {
    entry.points.reset(new pcl::PointCloud<pcl::PointXYZI>);
  }
  // Behind the LiDAR a return stays behind the camera while the vehicle drives forward.
  entry.points->clear();
  for (const auto& p : scan)
    if (p.x > 0.f)
      entry.points->push_back(p);
  entry.T_world_velo = T_world_velo;
  scans_.push_front(std::move(entry));
}

} // namespace msf
