// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/source_depth_frame.h>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// The maps of each depth source alone beside the fused one (msf_reconstruct
/// -compare_sources): the interpolated LiDAR and SGBM each integrated into a volume of their
/// own, configured as the engine's, from the same frames at the same poses, to see what the
/// fusion adds to the map.
class SourceMaps {
public:
  struct Map {
    DepthSource source;
    TsdfVolume volume;
    TsdfIntegrator integrator;
    TriangleMesh mesh;
    Map(DepthSource s, const PipelineConfig& config);
    /// "mesh_lidar" or "mesh_stereo".
    std::string name() const;
  };

  SourceMaps(const PipelineConfig& config, const Calibration& calibration);

  /// Integrates the frame's LiDAR and SGBM depth at its pose (the LiDAR's map also clears the
  /// scan's free space, as the fused map does; SGBM alone has none).
  void integrate(const FrameResult& result);
  /// Meshes every map.
  void mesh();
  std::vector<std::unique_ptr<Map>>& maps() { return maps_; }

private:
  PipelineConfig config_;
  const Calibration& calibration_;
  std::vector<std::unique_ptr<Map>> maps_;
};

} // namespace msf
