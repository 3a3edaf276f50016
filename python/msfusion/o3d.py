# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Open3D objects from msfusion's arrays, when Open3D is installed (Debian: python3-open3d);
msfusion does not need it otherwise.

    import msfusion.o3d
    open3d.visualization.draw_geometries([msfusion.o3d.to_triangle_mesh(mesh)])
"""
import numpy as np


def _open3d():
    try:
        import open3d
    except ImportError as e:
        raise ImportError("msfusion.o3d needs Open3D (Debian: apt-get install python3-open3d)") from e
    return open3d


def to_triangle_mesh(mesh):
    """An open3d.geometry.TriangleMesh of a msfusion.Mesh, with its vertex colours."""
    o3d = _open3d()
    out = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(mesh.vertices.astype(np.float64)),
        o3d.utility.Vector3iVector(mesh.triangles),
    )
    if len(mesh.colors) == len(mesh.vertices):
        out.vertex_colors = o3d.utility.Vector3dVector(mesh.colors.astype(np.float64) / 255.0)
    return out


def to_point_cloud(points, colors=None):
    """An open3d.geometry.PointCloud of (N, 3) points, with (N, 3) uint8 RGB colours if given
    (msfusion.depth_to_points gives both)."""
    o3d = _open3d()
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, dtype=np.float64)[:, :3]))
    if colors is not None:
        cloud.colors = o3d.utility.Vector3dVector(np.asarray(colors, dtype=np.float64) / 255.0)
    return cloud


def from_triangle_mesh(mesh):
    """A msfusion.Mesh of an open3d.geometry.TriangleMesh (its vertex colours if it has them)."""
    from ._core import Mesh

    vertices = np.ascontiguousarray(np.asarray(mesh.vertices), dtype=np.float32)
    triangles = np.ascontiguousarray(np.asarray(mesh.triangles), dtype=np.int32)
    colors = None
    if mesh.has_vertex_colors():
        colors = np.ascontiguousarray(np.clip(np.asarray(mesh.vertex_colors) * 255.0 + 0.5, 0, 255), dtype=np.uint8)
    return Mesh(vertices, triangles, colors)
