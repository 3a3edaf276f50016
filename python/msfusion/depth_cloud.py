# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The organized clouds the msf_* tools write, read as arrays."""
from ._core import _read_depth_cloud


class DepthCloud(tuple):
    """(depth, weight, color) of an organized .pcd, unpacked as a tuple of three, with what a fused
    cloud carries beside them as attributes: `free_space_weight` and `sky_depth` (NaN where the
    pixel is not open sky, else the depth its ray passed every surface to; +inf in the clear sky,
    clipped or blue, and where no LiDAR return bounds it). TsdfVolume.integrate takes them all, as
    msf_integrate reads them."""

    def __new__(cls, depth, weight, color, free_space_weight, sky_depth):
        cloud = super().__new__(cls, (depth, weight, color))
        cloud.free_space_weight = free_space_weight
        cloud.sky_depth = sky_depth
        return cloud

    depth = property(lambda self: self[0], doc="(H, W) float32 z in metres, 0 where the cloud has no point")
    weight = property(lambda self: self[1], doc="(H, W) float32 from the field weight, or None")
    color = property(lambda self: self[2], doc="(H, W, 3) uint8 RGB, or None")


def read_depth_cloud(path, camera=None):
    """An organized .pcd of camera 0 (msf_interpolate's, msf_stereo's, msf_fuse's) as a DepthCloud:
    depth (H, W) float32 z in metres (0 where NaN), weight (H, W) float32 or None, color (H, W, 3)
    uint8 RGB or None; free_space_weight (H, W) float32 or None and sky_depth (H, W) float32 or
    None as attributes. `camera` (a PinholeCamera) skips fitting the intrinsics to the points.
    Raises IOError naming the file, InvalidInputError for a cloud that is not organized or whose
    fields are not float32."""
    return DepthCloud(*_read_depth_cloud(str(path), camera))
