# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The examples of examples/python run as a user runs them, on KITTI odometry 04 (the drives on
its first 3 frames), and write what they say."""
import os
import subprocess
import sys

import numpy as np
import pytest

import msfusion


@pytest.fixture(scope="module")
def examples():
    return os.path.join(os.environ.get("MSF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                        "examples", "python")


def run(examples, name, *args):
    r = subprocess.run([sys.executable, os.path.join(examples, name), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"{name} failed: {r.stderr}"
    return r.stdout


def assert_mesh_of_the_drive(path, sequence):
    mesh = msfusion.read_mesh(str(path))
    assert len(mesh.triangles) > 10000 and mesh.colors.shape == mesh.vertices.shape
    # Within the map's reach (tsdf_integrator.max_depth_m and more) of the cameras, and coloured.
    cameras = sequence.poses[:, :3, 3]
    assert np.all(mesh.vertices.min(axis=0) > cameras.min(axis=0) - 100)
    assert np.all(mesh.vertices.max(axis=0) < cameras.max(axis=0) + 100)
    assert mesh.colors.std() > 10
    return mesh


def test_kitti_to_mesh(examples, odometry04, tmp_path):
    out = run(examples, "kitti_to_mesh.py", odometry04, tmp_path / "mesh.ply", 3)
    assert out.count("of the pixels have depth") == 3
    assert_mesh_of_the_drive(tmp_path / "mesh.ply", msfusion.Sequence(odometry04))


def test_per_stage(examples, odometry04, tmp_path):
    out = run(examples, "per_stage.py", odometry04, tmp_path / "mesh.ply", 3)
    assert out.count("of the pixels have depth") == 3
    assert_mesh_of_the_drive(tmp_path / "mesh.ply", msfusion.Sequence(odometry04))


def test_depth_of_one_frame(examples, odometry04, tmp_path):
    import matplotlib.image

    out = run(examples, "depth_of_one_frame.py", odometry04, 4, tmp_path / "depth.png")
    assert "fused depth at" in out
    picture = matplotlib.image.imread(str(tmp_path / "depth.png"))
    assert picture.ndim == 3 and picture.shape[0] > 600 and picture.shape[1] > 600
    assert picture[..., :3].std() > 0.1  # not a blank page
