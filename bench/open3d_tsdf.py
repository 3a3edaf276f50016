#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Open3D 0.16 ScalableTSDFVolume on the same depth images and poses as bench_tsdf.

bench_tsdf writes a folder with depth/NNNNNN.png (KITTI 16-bit depth, metres x 256),
color/NNNNNN.png, poses.txt (KITTI odometry format, T_world_cam) and camera.txt
(width height fx fy cx cy), then runs this script and prints both results side by side.

Prints one JSON object: integrate_ms_per_frame and extract_ms (wall) and the same as
process CPU time over all threads (*_cpu_*), medians over the repetitions, with the mesh size. Run with Debian's python3 (python3-open3d).
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np
import open3d as o3d


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("data", help="folder written by bench_tsdf")
    ap.add_argument("--voxel", type=float, default=0.1)
    ap.add_argument("--trunc", type=float, default=0.3)
    ap.add_argument("--max-depth", type=float, default=40.0)
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--mesh", help="also save the last mesh here (.ply)")
    args = ap.parse_args()

    with open(os.path.join(args.data, "camera.txt")) as f:
        w, h, fx, fy, cx, cy = f.read().split()
    intrinsic = o3d.camera.PinholeCameraIntrinsic(int(w), int(h), float(fx), float(fy), float(cx), float(cy))
    poses = []
    with open(os.path.join(args.data, "poses.txt")) as f:
        for line in f:
            if line.strip():
                T = np.eye(4)
                T[:3, :] = np.array([float(v) for v in line.split()]).reshape(3, 4)
                poses.append(T)
    names = sorted(os.listdir(os.path.join(args.data, "depth")))
    if len(names) != len(poses):
        sys.exit("open3d_tsdf: error: %d depth images but %d poses" % (len(names), len(poses)))

    # Images are read once, outside the timed part, as bench_tsdf holds its frames in memory.
    frames = []
    for name in names:
        depth = o3d.io.read_image(os.path.join(args.data, "depth", name))
        color = o3d.io.read_image(os.path.join(args.data, "color", name))
        frames.append(o3d.geometry.RGBDImage.create_from_color_and_depth(
            color, depth, depth_scale=256.0, depth_trunc=args.max_depth, convert_rgb_to_intensity=False))

    # Wall time, and the process's CPU time over all its threads (robust to a loaded machine).
    integrate_ms, extract_ms, integrate_cpu_ms, extract_cpu_ms = [], [], [], []
    mesh = None
    extrinsics = [np.linalg.inv(T) for T in poses]
    for _ in range(args.repetitions):
        volume = o3d.pipelines.integration.ScalableTSDFVolume(
            voxel_length=args.voxel, sdf_trunc=args.trunc,
            color_type=o3d.pipelines.integration.TSDFVolumeColorType.RGB8)
        t0, c0 = time.perf_counter(), time.process_time()
        for rgbd, T_cam_world in zip(frames, extrinsics):
            volume.integrate(rgbd, intrinsic, T_cam_world)
        integrate_ms.append((time.perf_counter() - t0) * 1e3 / len(frames))
        integrate_cpu_ms.append((time.process_time() - c0) * 1e3 / len(frames))
        t0, c0 = time.perf_counter(), time.process_time()
        mesh = volume.extract_triangle_mesh()
        extract_ms.append((time.perf_counter() - t0) * 1e3)
        extract_cpu_ms.append((time.process_time() - c0) * 1e3)
    if args.mesh:
        o3d.io.write_triangle_mesh(args.mesh, mesh)
    print(json.dumps({
        "open3d": o3d.__version__,
        "frames": len(frames),
        "integrate_ms_per_frame": statistics.median(integrate_ms),
        "extract_ms": statistics.median(extract_ms),
        "integrate_cpu_ms_per_frame": statistics.median(integrate_cpu_ms),
        "extract_cpu_ms": statistics.median(extract_cpu_ms),
        "vertices": len(mesh.vertices),
        "triangles": len(mesh.triangles),
    }))


if __name__ == "__main__":
    main()
