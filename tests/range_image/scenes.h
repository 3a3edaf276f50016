// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Small synthetic range images with known geometry for the range_image tests.
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>

#include <cmath>

namespace msf::test {

/// A 100 x 80 camera, f = 100 px, principal point (50, 40).
inline PinholeCamera smallCamera() {
  PinholeCamera c;
  c.fx = c.fy = 100.f;
  c.cx = 50.f;
  c.cy = 40.f;
  c.width = 100;
  c.height = 80;
  return c;
}

/// A calibration of smallCamera() for cameras 0..3 (camera i shifted by 0.5 i m to the
/// right), the LiDAR at the camera's centre with axes x forward, y left, z up.
inline Calibration smallCalibration() {
  Calibration c;
  for (int i = 0; i < 4; ++i) {
    c.P[i] << 100, 0, 50, -100 * 0.5 * i, 0, 100, 40, 0, 0, 0, 1, 0;
  }
  c.image_size = cv::Size(100, 80);
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0; // velodyne (fwd, left, up) -> camera (right, down, fwd)
  c.T_cam0_velo = Eigen::Isometry3d::Identity();
  c.T_cam0_velo.linear() = R;
  c.source = "smallCalibration";
  return c;
}

/// The true depth of a scene seen by smallCamera(): a ground plane below the horizon
/// (camera 1.5 m above it: 1/z = (v - cy) / (fy * 1.5)), a wall at 20 m above, and a box
/// at 5 m over columns [30, 60) and rows [20, 50).
inline float sceneDepth(int u, int v) {
  if (u >= 30 && u < 60 && v >= 20 && v < 50)
    return 5.f;
  const float ground = (static_cast<float>(v) - 40.f) / (100.f * 1.5f);
  const float wall = 1.f / 20.f;
  return 1.f / std::max(ground, wall);
}

/// The scene sampled like a scan: rings every `ring_step` rows, a return every
/// `column_step` columns along them (0 elsewhere).
inline cv::Mat sparseScene(int ring_step = 5, int column_step = 2) {
  cv::Mat d(80, 100, CV_32FC1, cv::Scalar(0));
  for (int v = 2; v < 80; v += ring_step)
    for (int u = (v / ring_step) % column_step; u < 100; u += column_step)
      d.at<float>(v, u) = sceneDepth(u, v);
  return d;
}

} // namespace msf::test
