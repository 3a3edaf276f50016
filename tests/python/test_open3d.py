# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""msfusion.o3d gives Open3D objects when Open3D is installed (python3-open3d, an optional
dependency: its tests are skipped without it), and names the package to install when it is not."""
import numpy as np
import pytest

import msfusion
import msfusion.o3d

try:
    import open3d as o3d
except ImportError:
    o3d = None

needs_open3d = pytest.mark.skipif(o3d is None, reason="Open3D is not installed (apt-get install python3-open3d): "
                                                      "msfusion.o3d is optional")


@pytest.mark.skipif(o3d is not None, reason="Open3D is installed")
def test_without_open3d_it_names_the_package_to_install():
    with pytest.raises(ImportError, match="apt-get install python3-open3d"):
        msfusion.o3d.to_point_cloud(np.zeros((1, 3), np.float32))


@needs_open3d

def test_a_mesh_goes_to_open3d_and_back():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.int32)
    colors = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [9, 8, 7]], np.uint8)
    mesh = msfusion.o3d.to_triangle_mesh(msfusion.Mesh(vertices, triangles, colors))
    assert isinstance(mesh, o3d.geometry.TriangleMesh)
    np.testing.assert_array_equal(np.asarray(mesh.vertices), vertices)
    np.testing.assert_array_equal(np.asarray(mesh.triangles), triangles)
    np.testing.assert_allclose(np.asarray(mesh.vertex_colors), colors / 255.0)
    back = msfusion.o3d.from_triangle_mesh(mesh)
    np.testing.assert_array_equal(back.vertices, vertices)
    np.testing.assert_array_equal(back.triangles, triangles)
    np.testing.assert_array_equal(back.colors, colors)


@needs_open3d
def test_points_go_to_an_open3d_cloud():
    points = np.array([[1, 2, 3], [4, 5, 6]], np.float32)
    cloud = msfusion.o3d.to_point_cloud(points, np.array([[255, 0, 0], [0, 0, 255]], np.uint8))
    np.testing.assert_array_equal(np.asarray(cloud.points), points)
    np.testing.assert_allclose(np.asarray(cloud.colors), [[1, 0, 0], [0, 0, 1]])
