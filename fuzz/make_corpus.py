#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Seed corpora of the fuzz targets, from the KITTI sample (../shared/data/kitti).

    make_corpus.py KITTI_DIR OUT_DIR

Writes OUT_DIR/<target>/<seed> for the targets cloud, ply, calibration, poses, velodyne and
config (its seeds are the project's own configuration files); the first byte of a seed picks
the format or reader where a target has several (see fuzz_*.cpp).
"""
import os
import struct
import sys

kitti, out = sys.argv[1], sys.argv[2]
seq = os.path.join(kitti, "odometry", "sequences", "04")
raw = os.path.join(kitti, "raw", "2011_09_26")


def put(target, name, data):
    d = os.path.join(out, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def read(path):
    with open(path, "rb") as f:
        return f.read()


# Velodyne: the first 100 and 1000 records of a scan, and a record cut short.
scan = read(os.path.join(seq, "velodyne", "000000.bin"))
put("velodyne", "scan100.bin", scan[:1600])
put("velodyne", "scan1000.bin", scan[:16000])
put("velodyne", "cut.bin", scan[:1602])

# Clouds: 64 points of that scan as ASCII and binary .pcd (organized 8x8 and not) and .ply.
pts = [struct.unpack_from("<4f", scan, 16 * i) for i in range(64)]
def pcd_header(data, width, height):
    return ("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            "WIDTH %d\nHEIGHT %d\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA %s\n" % (width, height, width * height, data))
def pcd(data, width, height):
    head = pcd_header(data, width, height)
    if data == "ascii":
        return head.encode() + "".join("%g %g %g %g\n" % p for p in pts).encode()
    return head.encode() + b"".join(struct.pack("<4f", *p) for p in pts)
put("cloud", "ascii.pcd", b"\0" + pcd("ascii", 64, 1))
put("cloud", "binary.pcd", b"\0" + pcd("binary", 8, 8))
# binary_compressed (what saveCloud writes): sizes, then the fields one after the other
# (all x, all y, ...) in LZF, here literal runs only (a control byte n < 32, then n + 1
# bytes); the fuzzer's mutations of the control bytes make the back references.
def lzf_literals(data):
    return b"".join(bytes([len(data[i:i + 32]) - 1]) + data[i:i + 32] for i in range(0, len(data), 32))
soa = b"".join(struct.pack("<64f", *(p[k] for p in pts)) for k in range(4))
packed = lzf_literals(soa)
put("cloud", "compressed.pcd", b"\0" + pcd_header("binary_compressed", 8, 8).encode() +
    struct.pack("<II", len(packed), len(soa)) + packed)
def ply(fmt):
    head = ("ply\nformat %s 1.0\nelement vertex 64\nproperty float x\nproperty float y\nproperty float z\n"
            "property float intensity\nend_header\n" % fmt)
    if fmt == "ascii":
        return head.encode() + "".join("%g %g %g %g\n" % p for p in pts).encode()
    return head.encode() + b"".join(struct.pack("<4f", *p) for p in pts)
put("cloud", "ascii.ply", b"\1" + ply("ascii"))
put("cloud", "binary.ply", b"\1" + ply("binary_little_endian"))

# PLY (fuzz_ply, first byte even: cloud, odd: mesh): the clouds above with colour; an
# organized 8x8 cloud as PCL writes it (obj_info num_cols and num_rows, a range_grid of the
# points, two of them missing); a mesh of triangles over the first points; and a header of
# comments near the 64 KB the header check reads, for mutations to cross it.
def ply_rgb(fmt, header_extra=""):
    head = ("ply\nformat %s 1.0\n%selement vertex 64\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n" % (fmt, header_extra))
    if fmt == "ascii":
        return head.encode() + "".join("%g %g %g 200 100 50\n" % p[:3] for p in pts).encode()
    return head.encode() + b"".join(struct.pack("<3f3B", *p[:3], 200, 100, 50) for p in pts)
put("ply", "ascii.ply", b"\0" + ply_rgb("ascii"))
put("ply", "binary.ply", b"\0" + ply_rgb("binary_little_endian"))
kept = [i for i in range(64) if i not in (5, 40)]
organized = ("ply\nformat binary_little_endian 1.0\ncomment PCL generated\nobj_info num_cols 8\nobj_info num_rows 8\n"
             "element vertex %d\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\n"
             "element range_grid 64\nproperty list uchar int vertex_indices\nend_header\n" % len(kept)).encode()
organized += b"".join(struct.pack("<4f", *pts[i]) for i in kept)
organized += b"".join(b"\0" if i not in kept else struct.pack("<Bi", 1, kept.index(i)) for i in range(64))
put("ply", "organized.ply", b"\0" + organized)
faces = [(i, i + 1, i + 8) for i in range(40)]
mesh = ("ply\nformat binary_little_endian 1.0\nelement vertex 64\nproperty float x\nproperty float y\n"
        "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces)).encode()
mesh += b"".join(struct.pack("<3f", *p[:3]) for p in pts) + b"".join(struct.pack("<B3i", 3, *f) for f in faces)
put("ply", "mesh.ply", b"\1" + mesh)
put("ply", "long_header.ply", b"\0" + ply_rgb("ascii", "comment %s\n" % ("x" * 60) * 900))

# Calibrations: odometry, object (made of the odometry one), raw folder, YAML.
odo = read(os.path.join(seq, "calib.txt"))
put("calibration", "odometry.txt", b"\0" + odo)
lines = dict(l.split(":", 1) for l in odo.decode().splitlines() if ":" in l)
obj = "".join("P%d:%s\n" % (i, lines["P%d" % i]) for i in range(4))
obj += "R0_rect: 1 0 0 0 1 0 0 0 1\nTr_velo_to_cam:%s\nTr_imu_to_velo:%s\n" % (lines["Tr"], lines["Tr"])
put("calibration", "object.txt", b"\1" + obj.encode())
parts = [read(os.path.join(raw, n)) for n in ("calib_cam_to_cam.txt", "calib_velo_to_cam.txt", "calib_imu_to_velo.txt")]
put("calibration", "raw.txt", b"\2" + b"\n===\n".join(parts))
put("calibration", "raw_no_imu.txt", b"\2" + b"\n===\n".join(parts[:2]))
def mat(name, rows, cols, values):
    return "%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: d\n   data: [ %s ]\n" % (
        name, rows, cols, ", ".join(values))
yaml = "%YAML:1.0\n---\n" + "".join(mat("P%d" % i, 3, 4, lines["P%d" % i].split()) for i in range(4))
yaml += "image_width: 1226\nimage_height: 370\n" + mat("T_cam0_velo", 4, 4, lines["Tr"].split() + ["0", "0", "0", "1"])
put("calibration", "camera.yaml", b"\3" + yaml.encode())
# A rig file (detected by its keys), and one nested 33000 levels deep (66 KB), beyond yaml-cpp's
# depth guard, whose mutations keep the fuzzer at that guard.
rig = ("image_width: 1226\nimage_height: 370\nleft: {P: [%s]}\nright: {P: [%s]}\nlidar:\n  T_cam_lidar: [%s]\n"
       "  rings: 4\n  beam_elevations_deg: [-15, -5, 5, 15]\n  sweeping: true\n" %
       (", ".join(lines["P0"].split()), ", ".join(lines["P1"].split()),
        ", ".join(lines["Tr"].split() + ["0", "0", "0", "1"])))
put("calibration", "rig.yaml", b"\3" + rig.encode())
put("calibration", "deep_rig.yaml", b"\3image_width: 640\nleft: " + b"[" * 33000 + b"]" * 33000 + b"\n")

# Poses: 20 odometry poses; one OXTS record.
poses = read(os.path.join(kitti, "odometry", "poses", "04.txt")).splitlines(True)
put("poses", "poses.txt", b"\1" + b"".join(poses[:20]))
oxts = os.path.join(raw, "2011_09_26_drive_0009_sync", "oxts", "data")
put("poses", "oxts.txt", b"\0" + read(os.path.join(oxts, sorted(os.listdir(oxts))[0])))

# Configurations: the shipped files, flow style, and a file nested 33000 levels deep (66 KB),
# beyond yaml-cpp's depth guard, whose mutations keep the fuzzer at that guard.
source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for name in ("kitti", "synthetic", "paper"):
    put("config", name + ".yaml", read(os.path.join(source, "config", name + ".yaml")))
put("config", "flow.yaml", b"stereo: {block_size_px: 7, mode: sgbm_3way}\nlambda_study: {noise_mm: [0, 5.5]}\n")
put("config", "deep.yaml", b"stereo:\n  p1: " + b"[" * 33000 + b"]" * 33000 + b"\n")
