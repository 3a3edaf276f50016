// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/pipeline/pipeline_config.h>

#include <cmath>
#include <ostream>

namespace msf {

void VolumeConfig::read(const cv::FileNode& node) {
  readKey(node, "voxel_size_m", voxel_size_m);
  readKey(node, "truncation_m", truncation_m);
  readKey(node, "max_memory_mb", max_memory_mb);
  validate();
}

void VolumeConfig::validate() const { TsdfVolume::validate(voxel_size_m, truncation_m, max_memory_mb); }

void VolumeConfig::print(std::ostream& out) const {
  out << "tsdf_volume:\n"
      << "  voxel_size_m: " << configValue(voxel_size_m) << "\n"
      << "  truncation_m: " << configValue(truncation_m) << "\n"
      << "  max_memory_mb: " << configValue(max_memory_mb) << "\n";
}

void SchedulingConfig::read(const cv::FileNode& node) {
  readKey(node, "queue_capacity", queue_capacity);
  readKey(node, "mesh_every_n_frames", mesh_every_n_frames);
  readKey(node, "stereo_prior", stereo_prior);
  // Removed with OpenMP: said so rather than "not a key", for configs printed before.
  if (node.isMap() && !node["lidar_threads"].empty())
    throw ConfigError("pipeline.lidar_threads was removed: the LiDAR steps run on OpenCV's pool like the other "
                      "stages (serially on the loader while another stage's loop holds it); delete the key");
  validate();
}

void SchedulingConfig::validate() const {
  if (queue_capacity < 1)
    throw ConfigError("pipeline.queue_capacity must be >= 1, got " + std::to_string(queue_capacity));
  if (mesh_every_n_frames < 0)
    throw ConfigError("pipeline.mesh_every_n_frames must be >= 0, got " + std::to_string(mesh_every_n_frames));
}

void SchedulingConfig::print(std::ostream& out) const {
  out << "pipeline:\n"
      << "  queue_capacity: " << configValue(queue_capacity) << "\n"
      << "  stereo_prior: " << configValue(stereo_prior) << "\n"
      << "  mesh_every_n_frames: " << configValue(mesh_every_n_frames) << "\n";
}

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
  // Step 5 (§III-C): a projective TSDF, every depth weighing the same, updated within the
  // truncation only, then eq. 7 solved to its minimizer with lambda 5 (the paper's KITTI value).
  c.integrator.weighting = TsdfIntegrator::Weighting::Constant;
  c.integrator.signed_distance = TsdfIntegrator::SignedDistance::Projective;
  c.integrator.truncation_sigmas = 0.0;
  c.integrator.min_pixel_weight = 0.f;
  c.integrator.space_carving = false;
  c.integrator.weight_dropoff = false;
  c.integrator.silhouette_band = false;
  c.integrator.interpolate_depth = false;
  c.integrator.lambda = 5.0;
  c.integrator.solve = TsdfIntegrator::Solve::Argmin;
  c.mesher.min_weight = 0.f;
  c.mesher.max_unseen_corners = 0;
  c.mesher.smoothing_lambda = 0.f;
  c.mesher.min_component_triangles = 0;
  c.validate();
  return c;
}

PipelineConfig PipelineConfig::load(const std::string& path) {
  PipelineConfig config;
  if (path.empty())
    return config;
  const ConfigFile file(path);
  config.projection.read(file.section("projection"));
  config.interpolation.read(file.section("interpolation"));
  config.rings.read(file.section("rings"));
  config.stereo.read(file.section("stereo"));
  config.fusion.read(file.section("fusion"));
  config.volume.read(file.section("tsdf_volume"));
  config.integrator.read(file.section("tsdf_integrator"));
  config.mesher.read(file.section("marching_cubes"));
  config.scheduling.read(file.section("pipeline"));
  config.streaming.read(file.section("streaming"));
  config.odometry.read(file.section("odometry"));
  config.rig.read(file.section("rig"));
  file.rejectUnknownKeys();
  config.validate();
  return config;
}

void PipelineConfig::validate() const {
  projection.validate();
  // Stereo matches cameras 0 and 1 and the map integrates in camera 0 at its pose: LiDAR in
  // another camera would be fused with pixels it does not cover.
  if (projection.camera != 0)
    throw ConfigError("projection.camera is " + std::to_string(projection.camera) +
                      ": the pipeline fuses the LiDAR with the stereo pair of cameras 0 and 1 in camera 0 "
                      "(msf_project -camera projects into another camera on its own)");
  interpolation.validate();
  rings.validate();
  stereo.validate();
  fusion.validate();
  volume.validate();
  integrator.validate();
  mesher.validate();
  scheduling.validate();
  streaming.validate();
  odometry.validate();
  rig.validate();
}

void PipelineConfig::print(std::ostream& out) const {
  out << "%YAML:1.0\n";
  projection.print(out);
  interpolation.print(out);
  rings.print(out);
  stereo.print(out);
  fusion.print(out);
  volume.print(out);
  integrator.print(out);
  mesher.print(out);
  scheduling.print(out);
  streaming.print(out);
  odometry.print(out);
  rig.print(out);
}

} // namespace msf
