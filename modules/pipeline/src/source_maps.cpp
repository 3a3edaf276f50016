// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/source_maps.h>

namespace msf {

SourceMaps::Map::Map(DepthSource s, const PipelineConfig& config)
    : source(s), volume(config.volume.voxel_size_m, config.volume.truncation_m), integrator(volume, config.integrator) {
  volume.setMaxMemoryMb(config.volume.max_memory_mb);
}

std::string SourceMaps::Map::name() const { return std::string("mesh_") + toString(source); }

SourceMaps::SourceMaps(const PipelineConfig& config, const Calibration& calibration)
    : config_(config), calibration_(calibration) {
  for (const DepthSource source : {DepthSource::Lidar, DepthSource::Stereo})
    maps_.push_back(std::make_unique<Map>(source, config_));
}

void SourceMaps::integrate(const FrameResult& result) {
  for (auto& map : maps_) {
    const DepthFrame frame = sourceDepthFrame(result, map->source, config_.fusion, calibration_.focalBaseline());
    map->integrator.integrateFrame(frame, result.T_world_cam0,
                                   freeSpaceOf(result, result.fused.camera, config_.fusion, calibration_,
                                               map->source == DepthSource::Lidar));
  }
}

void SourceMaps::mesh() {
  for (auto& map : maps_)
    MarchingCubes(config_.mesher).extract(map->volume, map->mesh);
}

} // namespace msf
