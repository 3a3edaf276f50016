# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The TSDF volume and the mesh on scenes with known answers (no data needed): a wall seen by a
pinhole camera or by a sensor's rays lands where it is, in the colour it has, and meshes keep
their arrays through a file."""
import copy
import pickle

import numpy as np
import pytest

import msfusion

CAMERA = msfusion.PinholeCamera(fx=200, fy=200, cx=200, cy=150, width=400, height=300)
WALL_COLOR = (200, 100, 50)  # RGB: a swapped channel would show


def wall(z=5.0):
    depth = np.full((CAMERA.height, CAMERA.width), z, np.float32)
    weight = np.full_like(depth, 1000.0)  # sigma 3 cm, a LiDAR-backed depth
    color = np.empty((CAMERA.height, CAMERA.width, 3), np.uint8)
    color[:] = WALL_COLOR
    return depth, weight, color


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def test_a_wall_meshes_where_it_is_in_its_colour():
    volume = msfusion.TsdfVolume(voxel_size=0.1, truncation=0.3)
    depth, weight, color = wall(5.0)
    volume.integrate(depth, translation(1.0, -2.0, 3.0), CAMERA, weight=weight, color=color)
    mesh = volume.extract_mesh()
    assert mesh.vertices.dtype == np.float32 and mesh.vertices.shape[1] == 3
    assert mesh.triangles.dtype == np.int32 and mesh.triangles.shape[1] == 3
    assert mesh.colors.dtype == np.uint8 and mesh.colors.shape == mesh.vertices.shape
    assert mesh.weights.shape == (len(mesh.vertices),)
    assert len(mesh.triangles) > 10000  # the wall is 10 m x 7.5 m: ~100 x 75 voxels
    np.testing.assert_allclose(mesh.vertices[:, 2], 8.0, atol=0.05)  # z 5 m from a camera at z 3 m
    assert mesh.vertices[:, 0].min() < 1.0 - 4.0 and mesh.vertices[:, 0].max() > 1.0 + 4.0
    assert (mesh.colors == WALL_COLOR).all()
    assert mesh.triangles.min() >= 0 and mesh.triangles.max() < len(mesh.vertices)
    assert volume.num_blocks > 0 and volume.num_observed_voxels > 0 and volume.memory_bytes > 0


def test_meshing_again_without_change_gives_the_same_mesh():
    volume = msfusion.TsdfVolume()
    depth, weight, color = wall(4.0)
    volume.integrate(depth, np.eye(4), CAMERA, weight=weight, color=color)
    first = volume.extract_mesh()
    second = volume.extract_mesh()  # incremental: no block changed
    np.testing.assert_array_equal(first.vertices, second.vertices)
    np.testing.assert_array_equal(first.triangles, second.triangles)


def test_points_with_a_pose_mesh_where_they_are():
    # A wall of points 6 m in front of a sensor looking along +z, every 2 cm.
    u, v = np.meshgrid(np.arange(-4.0, 4.0, 0.02), np.arange(-3.0, 3.0, 0.02))
    points = np.stack([u.ravel(), v.ravel(), np.full(u.size, 6.0)], axis=1).astype(np.float32)
    colors = np.tile(np.array(WALL_COLOR, np.uint8), (len(points), 1))
    volume = msfusion.TsdfVolume()
    volume.integrate_points(points, translation(0.0, 0.0, -1.0), colors=colors)
    mesh = volume.extract_mesh()
    assert len(mesh.triangles) > 1000
    np.testing.assert_allclose(np.median(mesh.vertices[:, 2]), 5.0, atol=0.05)  # 6 m from a sensor at z -1
    assert (mesh.colors == WALL_COLOR).all()
    with pytest.raises(msfusion.InvalidInputError, match="colors has 3 rows for"):
        volume.integrate_points(points, np.eye(4), colors=colors[:3].copy())


def test_a_mesh_and_a_camera_copy_and_pickle_whole():
    volume = msfusion.TsdfVolume(voxel_size=0.1, truncation=0.3)
    depth, weight, color = wall(5.0)
    volume.integrate(depth, np.eye(4), CAMERA, weight=weight, color=color)
    mesh = volume.extract_mesh()
    for twin in (copy.copy(mesh), copy.deepcopy(mesh), pickle.loads(pickle.dumps(mesh))):
        for name in ("vertices", "triangles", "colors", "weights"):
            np.testing.assert_array_equal(getattr(twin, name), getattr(mesh, name))
            assert not np.shares_memory(getattr(twin, name), getattr(mesh, name))
    bare = pickle.loads(pickle.dumps(msfusion.Mesh(mesh.vertices, mesh.triangles)))
    assert bare.colors.shape == (0, 3) and bare.weights.shape == (0,)
    for twin in (copy.copy(CAMERA), copy.deepcopy(CAMERA), pickle.loads(pickle.dumps(CAMERA))):
        assert repr(twin) == repr(CAMERA)
        twin.fx = 1.0  # a copy, not the camera itself
    assert CAMERA.fx == 200


def test_a_mesh_keeps_its_arrays_through_a_file(tmp_path):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.int32)
    colors = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [9, 8, 7]], np.uint8)
    mesh = msfusion.Mesh(vertices, triangles, colors)
    assert np.shares_memory(mesh.vertices, mesh.vertices) and repr(mesh) == "Mesh(4 vertices, 4 triangles)"
    for name in ("mesh.ply", "mesh.obj"):
        mesh.save(str(tmp_path / name))
        again = msfusion.read_mesh(str(tmp_path / name))
        np.testing.assert_array_equal(again.vertices, vertices)
        np.testing.assert_array_equal(again.triangles, triangles)
        if name.endswith(".ply"):
            np.testing.assert_array_equal(again.colors, colors)
    with pytest.raises(msfusion.InvalidInputError, match="triangles must be int32, got int64"):
        msfusion.Mesh(vertices, triangles.astype(np.int64))
    with pytest.raises(msfusion.InvalidInputError, match=r"triangles\[1\] refers to vertex 4 of 4"):
        msfusion.Mesh(vertices, np.array([[0, 1, 2], [1, 2, 4]], np.int32))
    with pytest.raises(msfusion.IOError, match="mesh.stl"):
        mesh.save(str(tmp_path / "mesh.stl"))
    with pytest.raises(msfusion.IOError, match="missing.ply"):
        msfusion.read_mesh(str(tmp_path / "missing.ply"))


def test_depth_to_points_puts_a_pixel_on_its_ray():
    depth = np.zeros((CAMERA.height, CAMERA.width), np.float32)
    depth[150, 300] = 2.0  # 100 px right of the principal point at fx 200: x = 1 m at 2 m
    color = np.zeros((CAMERA.height, CAMERA.width, 3), np.uint8)
    color[150, 300] = WALL_COLOR
    points, colors = msfusion.depth_to_points(depth, CAMERA, color=color, pose=translation(0, 0, 10))
    np.testing.assert_allclose(points, [[1.0, 0.0, 12.0]])
    np.testing.assert_array_equal(colors, [WALL_COLOR])


def test_depth_to_points_refuses_what_is_not_of_its_depth():
    depth = np.zeros((CAMERA.height, CAMERA.width), np.float32)
    cases = [
        (lambda: msfusion.depth_to_points(depth, "camera"),
         "camera must be a msfusion.PinholeCamera or a msfusion.Calibration, got str"),
        (lambda: msfusion.depth_to_points(depth[:10], CAMERA), r"depth must have shape \(%d, %d\)" % depth.shape),
        (lambda: msfusion.depth_to_points(depth, CAMERA, color=depth[:10]), "color must have shape"),
        (lambda: msfusion.depth_to_points(depth, CAMERA, pose=np.eye(3)),
         r"pose must have shape \(4, 4\), got \(3, 3\)"),
    ]
    for call, message in cases:
        with pytest.raises(msfusion.InvalidInputError, match=message):
            call()
