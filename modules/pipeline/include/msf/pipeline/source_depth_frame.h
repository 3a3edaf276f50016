#pragma once
#include <msf/pipeline/pipeline.h>
#include <msf/reconstruction/depth_frame.h>

namespace msf {

/// One input of the fusion, integrated alone into a volume of its own (msf_reconstruct
/// -compare_sources), to see what the fusion adds to the map.
enum class DepthSource {
  Lidar,  ///< the interpolated LiDAR (step 2), FrameResult::lidar_depth
  Stereo  ///< SGBM (step 3), FrameResult::stereo_depth
};

/// "lidar" or "stereo".
const char* toString(DepthSource source);

/// What the integrator gets from one source of a frame: the source's depth, the fused
/// colour (sampled at the fused depth) and weight 1 where the source has depth (0 elsewhere).
/// The one place that says how a single source is weighted: when the integrator's weighting
/// changes, this changes with it. Throws InvalidInputError when the frame has no depth of
/// that source or no fused colour.
DepthFrame sourceDepthFrame(const FrameResult& result, DepthSource source);

} // namespace msf
