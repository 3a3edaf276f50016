// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/ring_split.h>
#include <msf/range_image/scan_history.h>
#include <msf/registration/lidar_odometry.h>
#include <msf/reconstruction/map_raycaster.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/streaming_map.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/stereo/sgbm_config.h>

#include <iosfwd>
#include <string>

namespace msf {

class ConfigFile;

/// Section `tsdf_volume`: the grid of the map.
using VolumeConfig = TsdfVolume::Config;

/// Section `pipeline`: how msf_reconstruct schedules the stages.
struct SchedulingConfig {
  static constexpr const char* kSection = "pipeline";
  static constexpr const char* kAbout = "msf_reconstruct: how the stages are scheduled over their threads";
  int queue_capacity = 2;
  bool stereo_prior = true;
  int mesh_every_n_frames = 0;

  template <class Keys>
  void keys(Keys& k) {
    k("queue_capacity", queue_capacity, atLeast(1), "frames waiting between two stages");
    k("stereo_prior", stereo_prior,
      "SGBM searches only the disparities the interpolated LiDAR allows (stereo.prior_search_range)");
    k("mesh_every_n_frames", mesh_every_n_frames, atLeast(0), "refresh the mesh incrementally every n frames (0: never)");
    k.removed("lidar_threads", "the LiDAR steps run on OpenCV's pool like the other stages (serially on the loader "
                               "while another stage's loop holds it); delete the key");
  }
  void validate() const;
};

/// Every stage's configuration, read from one YAML file (config/kitti.yaml), one section
/// per stage, with the defaults of each stage's own Config where a key is absent.
struct PipelineConfig {
  ProjectionConfig projection;
  InterpolationConfig interpolation;
  ScanHistoryConfig accumulation; ///< earlier scans in the current view, before step 2
  /// Not a stage's: the ring hold-out of msf_reconstruct -holdout (protocols 2 and 4).
  RingSplitConfig rings;
  SgbmConfig stereo;
  DepthFusionConfig fusion;
  VolumeConfig volume;
  TsdfIntegrator::Config integrator;
  MapPriorConfig map_prior; ///< the map rendered into the view where the fused depth has none
  MarchingCubes::Config mesher;
  SchedulingConfig scheduling;
  StreamingMap::Config streaming; ///< the map in bounded memory (off by default)
  LidarOdometry::Config odometry; ///< the poses of msf_reconstruct -poses estimate (PoseSource)
  RigAdaptationConfig rig;        ///< how the keys above follow the rig the stages run on (adaptToRig)

  /// Calls visit(section) for each section of `config` (a PipelineConfig, const or not) in the
  /// order print() writes them.
  template <class Self, class Visit>
  static void forEachSection(Self& config, Visit&& visit) {
    visit(config.projection);
    visit(config.interpolation);
    visit(config.accumulation);
    visit(config.rings);
    visit(config.stereo);
    visit(config.fusion);
    visit(config.volume);
    visit(config.integrator);
    visit(config.map_prior);
    visit(config.mesher);
    visit(config.scheduling);
    visit(config.streaming);
    visit(config.odometry);
    visit(config.rig);
  }

  /// The paper as published (Ali, Rajput et al. 2019), without the project's additions:
  /// config/paper.yaml, and docs/paper.md for what each setting switches off and its effect.
  static PipelineConfig paper();

  /// Defaults overridden by the sections present in `path` ("" = all defaults), the whole
  /// file checked (openConfigFile). Throws IOError for a file that is not a config file,
  /// ConfigError naming the file, line and key of a bad section, key or value.
  static PipelineConfig load(const std::string& path);
  /// Overrides the keys `file` holds in each section, then validates. Throws ConfigError
  /// naming the file, line and key.
  void read(const ConfigFile& file);
  /// Throws ConfigError naming the first invalid key of any stage.
  void validate() const;
  /// Every key of every section above, as a YAML config file that load() (and PyYAML) reads
  /// back to the same configuration: what a run used, in full.
  void print(std::ostream& out) const;
};

} // namespace msf
