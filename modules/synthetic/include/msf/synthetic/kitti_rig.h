// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

namespace msf::synthetic {

/// KITTI's sensor rig as calibrated on 2011-09-26 (raw calib_cam_to_cam.txt: P_rect_00..03
/// and S_rect_00; calib_velo_to_cam.txt composed with R_rect_00): 1242x375 rectified images,
/// f = 721.5377 px, grey baseline 0.537 m, colour baseline 0.532 m; the Velodyne sits 0.08 m
/// above and 0.27 m behind camera 0. A dozen constants, not KITTI data.
Calibration kittiRig();

/// Height of camera 0 above the road, metres (KITTI: 1.65 m; the Velodyne is at 1.73 m).
constexpr double kCameraHeightM = 1.65;

} // namespace msf::synthetic
