# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""msfusion on numpy arrays: LiDAR and stereo fused into dense depth, and a sequence of those
into a coloured TSDF mesh (Ali, Rajput et al., IEEE Access 2019, and beyond).

Arrays in and out: images (H, W) uint8 grey or (H, W, 3) uint8 RGB, depth (H, W) float32 metres
(0 = none), scans (N, 4) float32 x y z reflectance, poses 4x4 float64 (T_world_cam), meshes as
vertices (V, 3) float32, triangles (T, 3) int32, colours (V, 3) uint8. Inputs are viewed where
they can be (C-contiguous arrays of the right dtype; anything else is an InvalidInputError that
names the argument), outputs are arrays that keep alive what they view (a FrameResult's and a
Mesh's arrays are views of it: copy one before editing it), and heavy calls release the GIL.

    import msfusion
    sequence = msfusion.Sequence("kitti/odometry/sequences/04")
    engine = msfusion.Reconstructor(sequence.calibration)
    for frame in sequence:
        result = engine.add_frame(frame)     # result.depth, result.weight, result.pose
    engine.mesh().save("mesh.ply")

Stage by stage: LidarCompletion, SgbmStereo, DepthFusion, colorize_depth, TsdfVolume; the
configuration of every stage: Config and load_config; Open3D objects: msfusion.o3d.
"""
from ._core import __commit__, __version__  # noqa: F401
from ._core import (  # noqa: F401  (the package's API)
    Calibration,
    CalibrationError,
    Config,
    ConfigError,
    DepthFusion,
    Error,
    Frame,
    FrameResult,
    FrameSource,
    InvalidInputError,
    IOError,
    LidarCompletion,
    Mesh,
    PinholeCamera,
    Reconstructor,
    SgbmStereo,
    Sequence,
    TsdfVolume,
    colorize_depth,
    get_num_threads,
    load_calibration,
    open_dataset,
    read_mesh,
    real_returns,
    set_num_threads,
    use_huge_pages_for_large_images,
)
from .config import load_config  # noqa: F401
from .depth_cloud import DepthCloud, read_depth_cloud  # noqa: F401
from .geometry import depth_to_points  # noqa: F401

# What `from msfusion import *` gives and `help(msfusion)` documents (the classes live in _core).
__all__ = [
    "Calibration", "CalibrationError", "Config", "ConfigError", "DepthCloud", "DepthFusion", "Error", "Frame",
    "FrameResult", "FrameSource", "IOError", "InvalidInputError", "LidarCompletion", "Mesh", "PinholeCamera",
    "Reconstructor", "SgbmStereo", "Sequence", "TsdfVolume", "colorize_depth", "depth_to_points", "get_num_threads",
    "load_calibration", "load_config", "open_dataset", "read_depth_cloud", "read_mesh", "real_returns",
    "set_num_threads", "use_huge_pages_for_large_images",
]
