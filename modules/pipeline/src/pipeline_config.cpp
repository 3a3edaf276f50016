// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/pipeline/pipeline_config.h>

#include <cmath>
#include <ostream>

namespace msf {

void SchedulingConfig::validate() const { checkKeyRanges(*this); }

PipelineConfig PipelineConfig::paper() {
  PipelineConfig c;
  // Step 1: the scan into the image only (no canvas around it).
  c.projection.margin_px = 0;
  // Step 2 (§III-B): eq. 2-5 on depth z; rows and columns sliced independently and averaged
  // where both bridge a pixel; every gap up to the maximum bridged (no edge test); one
  // Gaussian pass over the result (the real returns kept).
  c.interpolation.slice.interpolant = SliceInterpolant::Compound;
  c.interpolation.slice.inverse_depth = false;
  c.interpolation.slice.edge_test = false;
  c.interpolation.slice.cubic_alpha = 2.f;
  c.interpolation.slice.cubic_beta = 3.f;
  c.interpolation.column_seed_gap_px = 0;
  c.interpolation.combine = CombineRule::Average;
  c.interpolation.gaussian = true;
  c.interpolation.gaussian_smooth_valid = true;
  // Step 3: OpenCV's SGBM on the grey pair alone, over the full disparity range.
  c.stereo.engine = "opencv";
  c.stereo.mode = "sgbm_3way";
  c.stereo.unguided_mode = "sgbm_3way";
  c.stereo.guidance = "none";
  c.stereo.prior_search_range = false;
  c.scheduling.stereo_prior = false;
  // Step 4: eq. 6 with the paper's weights, nothing after it.
  c.fusion.method = FusionMethod::Paper;
  c.fusion.paper_weights = PaperWeights::AsWritten;
  c.fusion.edge_support = false;
  c.fusion.facade_extension = false;
  c.fusion.clear_sky = false;
  // Step 5 (§III-C): a projective TSDF, every depth weighing the same, updated within the
  // truncation only, then eq. 7 solved to its minimizer with lambda 5 (the paper's KITTI value).
  c.integrator.weighting = TsdfIntegrator::Weighting::Constant;
  c.integrator.signed_distance = TsdfIntegrator::SignedDistance::Projective;
  c.integrator.truncation_sigmas = 0.0;
  c.integrator.min_pixel_weight = 0.f;
  c.integrator.space_carving = false;
  c.integrator.sky_carving = false;
  c.integrator.far_carving = false;
  c.integrator.weight_dropoff = false;
  c.integrator.silhouette_band = false;
  c.integrator.interpolate_depth = false;
  c.integrator.lambda = 5.0;
  c.integrator.solve = TsdfIntegrator::Solve::Argmin;
  c.map_prior.enabled = false;
  c.fusion.hole_fill_px = 0;
  c.mesher.min_weight = 0.f;
  c.mesher.max_unseen_corners = 0;
  c.mesher.smoothing_lambda = 0.f;
  c.mesher.min_component_triangles = 0;
  c.validate();
  return c;
}

PipelineConfig PipelineConfig::load(const std::string& path) {
  PipelineConfig config;
  if (!path.empty())
    config.read(openConfigFile(path));
  return config;
}

void PipelineConfig::read(const ConfigFile& file) {
  forEachSection(*this, [&](auto& section) { file.read(section); });
  try {
    validate();
  } catch (const ConfigError& e) {
    file.rethrowInFile(e);
  }
}

void PipelineConfig::validate() const {
  forEachSection(*this, [](const auto& section) { section.validate(); });
  // Stereo matches cameras 0 and 1 and the map integrates in camera 0 at its pose: LiDAR in
  // another camera would be fused with pixels it does not cover.
  if (projection.camera != 0)
    throw ConfigError("projection.camera is " + std::to_string(projection.camera) +
                      ": the pipeline fuses the LiDAR with the stereo pair of cameras 0 and 1 in camera 0 "
                      "(msf_project -camera projects into another camera on its own)");
}

void PipelineConfig::print(std::ostream& out) const {
  forEachSection(*this, [&](const auto& section) { printConfig(out, section); });
}

} // namespace msf
