// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/ring_split.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/stereo/sgbm_config.h>

#include <iosfwd>
#include <string>

namespace msf {

/// Section `tsdf_volume`: the grid of the map.
struct VolumeConfig {
  double voxel_size_m = 0.1;
  double truncation_m = 0.3;
  double max_memory_mb = 0.0; ///< the volume's memory budget, 0 = three quarters of RAM (TsdfVolume::Config)

  void read(const cv::FileNode& node);
  /// Throws ConfigError naming the key of a value out of range.
  void validate() const;
  void print(std::ostream& out) const;
};

/// Section `pipeline`: how the stages are scheduled and what is kept.
struct SchedulingConfig {
  int queue_capacity = 2;        ///< frames waiting between two stages
  bool stereo_prior = true;      ///< SGBM narrowed by the interpolated LiDAR (stereo.prior_search_range)
  int mesh_every_n_frames = 0;   ///< > 0: refresh the mesh incrementally every n frames
  void read(const cv::FileNode& node);
  void validate() const;
  void print(std::ostream& out) const;
};

/// Every stage's configuration, read from one YAML file (config/kitti.yaml), one section
/// per stage, with the defaults of each stage's own Config where a key is absent.
struct PipelineConfig {
  ProjectionConfig projection;              ///< `projection`
  InterpolationConfig interpolation;        ///< `interpolation`
  /// `rings`: not a stage's; the ring hold-out of msf_reconstruct -holdout (protocols 2 and 4)
  RingSplitConfig rings;
  SgbmConfig stereo;                        ///< `stereo`
  DepthFusionConfig fusion;                 ///< `fusion`
  VolumeConfig volume;                      ///< `tsdf_volume`
  TsdfIntegrator::Config integrator;        ///< `tsdf_integrator`
  MarchingCubes::Config mesher;             ///< `marching_cubes`
  SchedulingConfig scheduling;              ///< `pipeline`
  StreamingMap::Config streaming;           ///< `streaming`: the map in bounded memory (off by default)
  /// `odometry`: the poses of msf_reconstruct -poses estimate (PoseSource)
  LidarOdometry::Config odometry;
  /// `rig`: how the keys above follow the rig the stages run on (adaptToRig)
  RigAdaptationConfig rig;

  /// The paper as published (Ali, Rajput et al. 2019), without the project's additions:
  /// config/paper.yaml, and docs/paper.md for what each setting switches off and its effect.
  static PipelineConfig paper();

  /// Defaults overridden by the sections present in `path` ("" = all defaults).
  /// Throws IOError for a missing file, ConfigError naming a bad key.
  static PipelineConfig load(const std::string& path);
  /// Throws ConfigError naming the first invalid key of any stage.
  void validate() const;
  /// Every key of every section above, as a YAML config file that load() reads back to the
  /// same configuration: what a run used, in full (each section's own print()).
  void print(std::ostream& out) const;
};

} // namespace msf
