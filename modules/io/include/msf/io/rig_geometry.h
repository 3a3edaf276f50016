// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

namespace msf {

/// What the stages' sizes follow from on any rig: the grey pair's f·B (disparity = f·B / depth)
/// and how many image rows of camera 0 lie between two of the LiDAR's rings.
struct RigGeometry {
  double focal_baseline = 0.0; ///< f·B of cameras 0 and 1, px·m
  double rows_per_ring = 0.0;  ///< fy · the beams' mean spacing in radians; 0 when the rig lists no beams

  /// Throws CalibrationError as Calibration::focalBaseline does.
  static RigGeometry of(const Calibration& calibration);
  /// KITTI's: an HDL-64E (+2.0 .. -24.9 degrees over 63 spacings, the synthetic street's beams)
  /// seen by the 2011_09_26 cameras (fy 721.5377 px): 5.377 rows.
  static double kittiRowsPerRing();
  /// rows_per_ring over KITTI's; 1 when the beams are unknown (KITTI's calibration files list none).
  double ringScale() const;
  /// Depth of a disparity of the grey pair, metres.
  double depthAtDisparity(double disparity_px) const { return focal_baseline / disparity_px; }
};

} // namespace msf
