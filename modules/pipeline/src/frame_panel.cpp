// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/frame_panel.h>

namespace msf {

cv::Mat framePanel(const FrameResult& r, bool input_rings_only, const cv::Mat& true_depth) {
  constexpr float kNearM = 3.f, kFarM = 60.f;
  DepthPanel panel;
  panel.addImage("left image (camera 0), frame " + r.name, r.left);
  if (!r.lidar_sparse.empty())
    panel.addDepth(input_rings_only ? "projected LiDAR (input rings)" : "projected LiDAR", r.lidar_sparse, kNearM,
                   kFarM, 1);
  panel.addDepth("interpolated LiDAR", r.lidar_depth, kNearM, kFarM);
  panel.addDepth("SGBM", r.stereo_depth, kNearM, kFarM);
  panel.addDepth("fused", r.fused.depth, kNearM, kFarM);
  if (!true_depth.empty())
    panel.addError("|fused - ground truth|", r.fused.depth, true_depth, 2.f);
  return panel.render();
}

} // namespace msf
