# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Depth images to points, in numpy: what a notebook plots or hands to another library."""
import numpy as np

from ._core import Calibration, InvalidInputError, PinholeCamera, _rigid_pose


def depth_to_points(depth, camera, color=None, pose=None):
    """The points of a depth image: pixel (u, v) with depth z > 0 becomes
    ((u - cx) z / fx, (v - cy) z / fy, z) in the camera's frame, or in the world with a 4x4
    `pose` (T_world_cam). `camera` is a PinholeCamera (Calibration.camera()) or a Calibration
    (its camera 0). Returns points (M, 3) float32, and with an (H, W, 3) or (H, W) `color` of the
    depth's size also its (M, 3) or (M,) colours. Raises InvalidInputError naming the argument."""
    if isinstance(camera, Calibration):
        camera = camera.camera(0)
    if not isinstance(camera, PinholeCamera):
        raise InvalidInputError(f"camera must be a msfusion.PinholeCamera or a msfusion.Calibration, "
                                f"got {type(camera).__name__}")
    depth = np.asarray(depth)
    if depth.ndim != 2 or depth.shape != (camera.height, camera.width):
        raise InvalidInputError(f"depth must have shape ({camera.height}, {camera.width}) of the camera, "
                                f"got {depth.shape}")
    if color is not None:
        color = np.asarray(color)
        if color.shape[:2] != depth.shape or color.ndim not in (2, 3):
            raise InvalidInputError(f"color must have shape {depth.shape} or {depth.shape + (3,)} of the depth, "
                                    f"got {color.shape}")
    if pose is not None:
        pose = _rigid_pose(np.asarray(pose, dtype=np.float64), "pose")
    v, u = np.nonzero(np.isfinite(depth) & (depth > 0))
    z = depth[v, u].astype(np.float32)
    points = np.stack([(u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z], axis=1).astype(np.float32)
    if pose is not None:
        points = (points @ pose[:3, :3].T + pose[:3, 3]).astype(np.float32)
    if color is None:
        return points
    return points, color[v, u]
