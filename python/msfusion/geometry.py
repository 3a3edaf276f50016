# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Depth images to points, in numpy: what a notebook plots or hands to another library."""
import numpy as np


def depth_to_points(depth, camera, color=None, pose=None):
    """The points of a depth image: pixel (u, v) with depth z > 0 becomes
    ((u - cx) z / fx, (v - cy) z / fy, z) in the camera's frame, or in the world with a 4x4
    `pose` (T_world_cam). `camera` is a PinholeCamera (Calibration.camera()). Returns points
    (M, 3) float32, and with an (H, W, 3) `color` also its (M, 3) colours."""
    depth = np.asarray(depth)
    if depth.ndim != 2 or depth.shape != (camera.height, camera.width):
        raise ValueError(f"depth must have shape ({camera.height}, {camera.width}) of the camera, got {depth.shape}")
    v, u = np.nonzero(np.isfinite(depth) & (depth > 0))
    z = depth[v, u].astype(np.float32)
    points = np.stack([(u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z], axis=1).astype(np.float32)
    if pose is not None:
        pose = np.asarray(pose, dtype=np.float64)
        points = (points @ pose[:3, :3].T + pose[:3, 3]).astype(np.float32)
    if color is None:
        return points
    return points, np.asarray(color)[v, u]
