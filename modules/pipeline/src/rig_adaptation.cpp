// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config_keys.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/rig_adaptation.h>

#include <algorithm>
#include <cmath>

namespace msf {

void RigAdaptationConfig::validate() const { checkKeyRanges(*this); }

namespace {

int scaled(int rows, double scale) { return std::max(1, static_cast<int>(std::lround(rows * scale))); }

/// An odd window stays odd (its centre is a pixel).
int scaledOdd(int rows, double scale) {
  const int r = scaled(rows, scale);
  return r % 2 == 1 ? r : r + 1;
}

} // namespace

RigAdaptation rigAdaptation(const RigAdaptationConfig& config, const Calibration& rig) {
  RigAdaptation a;
  a.geometry = RigGeometry::of(rig);
  if (config.scale_ring_rows)
    a.ring_scale = a.geometry.ringScale();
  if (config.stereo_min_disparity_px > 0.0)
    a.stereo_trusted_depth_m = a.geometry.depthAtDisparity(config.stereo_min_disparity_px);
  return a;
}

void adaptToRig(InterpolationConfig& interpolation, const RigAdaptation& rig) {
  if (rig.ring_scale == 1.0)
    return;
  interpolation.slice.short_gap_px = scaled(interpolation.slice.short_gap_px, rig.ring_scale);
  interpolation.slice.max_gap_px = scaled(interpolation.slice.max_gap_px, rig.ring_scale);
}

void adaptToRig(SgbmConfig& stereo, const RigAdaptation& rig) {
  if (rig.ring_scale != 1.0)
    stereo.guidance_bridge_rows = scaled(stereo.guidance_bridge_rows, rig.ring_scale);
}

void adaptToRig(DepthFusionConfig& fusion, const RigAdaptation& rig) {
  if (rig.ring_scale == 1.0)
    return;
  fusion.edge_window_rows = scaledOdd(fusion.edge_window_rows, rig.ring_scale);
  fusion.parallax_max_rows = scaled(fusion.parallax_max_rows, rig.ring_scale);
}

void adaptToRig(TsdfIntegrator::Config& integrator, const RigAdaptation& rig) {
  if (rig.stereo_trusted_depth_m > 0.0)
    integrator.max_depth_m = std::min(integrator.max_depth_m, rig.stereo_trusted_depth_m);
}

PipelineConfig adaptToRig(const PipelineConfig& config, const Calibration& rig, RigAdaptation* adaptation) {
  RigAdaptation a = rigAdaptation(config.rig, rig);
  PipelineConfig c = config;
  adaptToRig(c.interpolation, a);
  adaptToRig(c.stereo, a);
  adaptToRig(c.fusion, a);
  adaptToRig(c.integrator, a);
  a.max_depth_m = c.integrator.max_depth_m;
  c.validate();
  if (adaptation)
    *adaptation = a;
  return c;
}

} // namespace msf
