// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/reconstruction/depth_frame.h>

namespace msf {

// What the integrator gets from a frame of the pipeline.

/// The fused depth of `result`, with its weight and colour, grown to the LiDAR's canvas: the
/// interpolated LiDAR fills the margin around the image (weighed as the fusion weighs the
/// LiDAR, lidarDepthWeight; the image's border colours repeated). So the edge of what the frame
/// adds to the map (marching cubes needs voxels seen on both sides of a surface) lies outside
/// the camera's view rather than a voxel inside it. The fused frame itself when the frame has no
/// canvas.
DepthFrame fusedDepthFrame(const FrameResult& result, const DepthFusionConfig& fusion, double focal_baseline);

/// One input of the fusion, integrated alone into a volume of its own (msf_reconstruct
/// -compare_sources), to see what the fusion adds to the map.
enum class DepthSource {
  Lidar,  ///< the interpolated LiDAR (step 2), FrameResult::lidar_depth
  Stereo  ///< SGBM (step 3), FrameResult::stereo_depth
};

/// "lidar" or "stereo".
const char* toString(DepthSource source);

/// What the integrator gets from one source of a frame: the source's depth (the LiDAR's on its
/// canvas, as fusedDepthFrame), the fused colour (sampled at the fused depth) and, as the fused
/// depth's, the inverse variance of
/// each depth by the fusion's own model of that source: lidarDepthWeight of lidarSigmaPx (the
/// distance to the nearest real return and the local disparity range: the LiDAR alone has no
/// stereo to settle its edges), depthWeight of stereoSigmaPx from SGBM's confidence. Throws
/// InvalidInputError when the frame has no depth of that source, a cue image of another
/// size, no fused colour, or f B is not > 0.
DepthFrame sourceDepthFrame(const FrameResult& result, DepthSource source, const DepthFusionConfig& fusion,
                            double focal_baseline);

} // namespace msf
