// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/statistics.h>
#include <msf/pipeline/rig_agreement.h>

#include <cmath>
#include <cstdio>

namespace msf {

double lidarStereoDisagreement(const cv::Mat& lidar_depth, const cv::Mat& lidar_distance,
                               const cv::Mat& stereo_depth) {
  std::size_t both = 0, differ = 0;
  const float relative = static_cast<float>(kDisagreementRelative);
  for (int v = 0; v < lidar_depth.rows; ++v) {
    const float* lidar = lidar_depth.ptr<float>(v);
    const float* distance = lidar_distance.ptr<float>(v);
    const float* stereo = stereo_depth.ptr<float>(v);
    // Without a branch, so that the compiler vectorizes the row.
    for (int u = 0; u < lidar_depth.cols; ++u) {
      const bool measured = (lidar[u] > 0.f) & (distance[u] == 0.f) & (stereo[u] > 0.f);
      both += measured;
      differ += measured & (std::abs(stereo[u] - lidar[u]) > relative * lidar[u]);
    }
  }
  return both ? static_cast<double>(differ) / static_cast<double>(both) : std::nan("");
}

double medianDisagreement(const std::vector<double>& shares) {
  std::vector<double> measured;
  for (const double share : shares)
    if (std::isfinite(share))
      measured.push_back(share);
  return measured.empty() ? std::nan("") : median(measured);
}

std::string rigDisagreementWarning(const std::vector<double>& shares) {
  const double share = medianDisagreement(shares);
  if (!(share > kRigDisagreementWarning))
    return "";
  char text[400];
  std::snprintf(text, sizeof text,
                "the LiDAR and stereo disagree by more than %.0f %% on %.0f %% of the pixels both measure (median "
                "over the frames; a right rig gives a few percent): check the rig's LiDAR extrinsic (the "
                "LiDAR-to-camera transform, not its inverse), the baseline and the units",
                100 * kDisagreementRelative, 100 * share);
  return text;
}

} // namespace msf
