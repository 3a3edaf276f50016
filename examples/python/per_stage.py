# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""A KITTI drive to a mesh stage by stage, each stage a call on numpy arrays:
PYTHONPATH=build/python /usr/bin/python3 examples/python/per_stage.py SEQUENCE_DIR MESH.ply [FRAMES]
(from the repository, with the build tree's module; see docs/python.md)

The pipeline (kitti_to_mesh.py) chains the same stages; it also integrates the interpolated
LiDAR beyond the image's border and clears free space with the whole scan, so its mesh is a
little larger."""
import itertools
import sys

import msfusion

if len(sys.argv) < 3:
    sys.exit(__doc__)  # the usage

sequence = msfusion.Sequence(sys.argv[1])
calibration = sequence.calibration
lidar = msfusion.LidarCompletion(calibration)   # steps 1-2: projection and compound interpolation
stereo = msfusion.SgbmStereo(calibration)       # step 3: semi-global matching
fusion = msfusion.DepthFusion(calibration)      # step 4: per-pixel fusion
volume = msfusion.TsdfVolume()                  # step 5: TSDF volume and marching cubes

for frame in itertools.islice(sequence, int(sys.argv[3]) if len(sys.argv) > 3 else None):
    lidar_depth, distance = lidar.compute_depth(frame.scan)            # (N, 4) float32 -> (H, W) float32
    stereo_depth, confidence = stereo.compute_depth(
        frame.left, frame.right,                                       # (H, W) uint8
        prior=lidar_depth,                                             # narrows the disparity search
        guidance=msfusion.real_returns(lidar_depth, distance))         # the real returns guide the matching
    depth, weight = fusion.fuse(lidar_depth, distance, stereo_depth, confidence,
                                left=frame.left, sky=frame.color)  # no depth in the clear sky
    color = msfusion.colorize_depth(depth, calibration, frame.color, fallback=frame.left)
    volume.integrate(depth, frame.pose, calibration, weight=weight, color=color)  # 4x4 T_world_cam0
    print(f"frame {frame.name}: {(depth > 0).mean():.0%} of the pixels have depth, {volume.num_blocks} blocks")

mesh = volume.extract_mesh()  # vertices (V, 3) float32, triangles (T, 3) int32, colors (V, 3) uint8
mesh.save(sys.argv[2])
print(f"{len(mesh.vertices)} vertices, {len(mesh.triangles)} triangles -> {sys.argv[2]}")
