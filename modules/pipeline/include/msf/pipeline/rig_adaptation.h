// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/rig_geometry.h>

#include <opencv2/core/persistence.hpp>

#include <iosfwd>

namespace msf {

struct PipelineConfig;

/// Section `rig`: how the stages follow the rig they run on (docs/design.md, "Any rig").
/// The keys of the other sections are KITTI's sizes; adaptToRig turns them into the rig's.
struct RigAdaptationConfig {
  /// Depth not known to within the truncation by its own weight (stereo's) is integrated, and the
  /// map scored, up to the depth of this disparity of the grey pair, f·B / it, and at most
  /// tsdf_integrator.max_depth_m; 0: max_depth_m alone.
  double stereo_min_disparity_px = 8.0;
  /// Keys counted in rows between the LiDAR's rings scale by the rig's rows per ring over KITTI's
  /// (RigGeometry::ringScale; 1 when the rig lists no beams).
  bool scale_ring_rows = true;

  void read(const cv::FileNode& node);
  /// Throws ConfigError naming the key out of range.
  void validate() const;
  void print(std::ostream& out) const;
};

/// What adaptToRig derived, for the run's report.
struct RigAdaptation {
  RigGeometry geometry;
  double ring_scale = 1.0;     ///< the factor applied to keys in rows between rings
  double max_depth_m = 0.0;    ///< the range of imprecise depth and of the map's scores
  double stereo_trusted_depth_m = 0.0; ///< f·B / stereo_min_disparity_px (0: not set)
};

/// The configuration the stages run with on `rig`: the keys in rows between LiDAR rings
/// (interpolation gaps and its Gaussian, the fusion's edge and parallax windows, the guidance's
/// bridge) times the ring scale, rounded (windows kept odd), and tsdf_integrator.max_depth_m
/// capped at stereo's trusted depth. KITTI's calibrations list no beams and give f·B / 8 px
/// beyond 40 m: the configuration comes back unchanged. `adaptation` receives what was derived.
PipelineConfig adaptToRig(const PipelineConfig& config, const Calibration& rig, RigAdaptation* adaptation = nullptr);

} // namespace msf
