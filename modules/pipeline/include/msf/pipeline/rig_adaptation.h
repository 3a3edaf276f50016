// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/common/config_keys.h>
#include <msf/io/calibration.h>
#include <msf/io/rig_geometry.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/stereo/sgbm_config.h>

#include <string>

namespace msf {

struct PipelineConfig;

/// Section `rig`: how the stages follow the rig they run on (docs/design.md, "Any rig").
/// The keys of the other sections are KITTI's sizes; adaptToRig turns them into the rig's.
struct RigAdaptationConfig {
  static constexpr const char* kSection = "rig";
  static constexpr const char* kAbout = "how the keys of the other sections (KITTI's sizes) follow the rig the "
                                        "stages run on (adaptToRig; docs/design.md, \"Any rig\")";
  double stereo_min_disparity_px = 8.0;
  bool scale_ring_rows = true;

  template <class Keys>
  void keys(Keys& k) {
    k("stereo_min_disparity_px", stereo_min_disparity_px, between(0, 1000),
      "depth not known to within the truncation by its own weight (stereo's) is integrated, and the map scored, up "
      "to the depth of this disparity of the grey pair, f*B / it, and at most tsdf_integrator.max_depth_m; 0: "
      "max_depth_m alone");
    k("scale_ring_rows", scale_ring_rows,
      "keys counted in rows between the LiDAR's rings scale by the rig's rows per ring over KITTI's (1 when the rig "
      "lists no beams)");
  }
  /// Throws ConfigError naming the key out of range.
  void validate() const;
};

/// What the rig gives the keys (rigAdaptation), and what adaptToRig derived, for the run's report.
struct RigAdaptation {
  RigGeometry geometry;
  double ring_scale = 1.0;     ///< the factor applied to keys in rows between rings
  double max_depth_m = 0.0;    ///< the range of imprecise depth and of the map's scores (adaptToRig)
  double stereo_trusted_depth_m = 0.0; ///< f·B / stereo_min_disparity_px (0: not set)
};

/// The ring scale (1 when `config` turns it off or the rig lists no beams) and stereo's trusted
/// depth (0 when turned off) of `rig`. Throws CalibrationError as Calibration::focalBaseline does.
RigAdaptation rigAdaptation(const RigAdaptationConfig& config, const Calibration& rig);

/// One stage's keys on the rig, as adaptToRig sets them for the engine: what the tools that run
/// one stage (msf_interpolate, msf_stereo, msf_fuse, msf_integrate) apply under -rig.
void adaptToRig(InterpolationConfig& interpolation, const RigAdaptation& rig); ///< short_gap_px, max_gap_px
void adaptToRig(SgbmConfig& stereo, const RigAdaptation& rig);                 ///< guidance_bridge_rows
void adaptToRig(DepthFusionConfig& fusion, const RigAdaptation& rig); ///< edge_window_rows (odd), parallax_max_rows
void adaptToRig(TsdfIntegrator::Config& integrator, const RigAdaptation& rig); ///< max_depth_m

/// The configuration the stages run with on `rig`: the keys in rows between LiDAR rings
/// (the interpolation's gaps, the fusion's edge and parallax windows, the guidance's bridge)
/// times the ring scale, rounded (windows kept odd), and tsdf_integrator.max_depth_m capped at
/// stereo's trusted depth. KITTI's calibrations list no beams and give f·B / 8 px beyond 40 m:
/// the configuration comes back unchanged. `adaptation` receives what was derived.
PipelineConfig adaptToRig(const PipelineConfig& config, const Calibration& rig, RigAdaptation* adaptation = nullptr);

} // namespace msf
