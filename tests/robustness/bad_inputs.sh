#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# The bad-input matrix: hostile or mistaken inputs against the msf_* tools.
# Every case must end in under 5 s and under 500 MB, with the exit code it expects (1: a
# clear error; 0: a result, e.g. with a warning) and a message matching a pattern that names
# the option, key or file at fault; a failed run must leave no output file behind.
#
#   tests/robustness/bad_inputs.sh BIN_DIR KITTI_DIR
#
# Prints one line a case and a summary; exits 1 when any case fails. KITTI_DIR is the
# KITTI sample (../shared/data/kitti); the cases that need it are skipped without it unless
# CI=true.
#
#   tests/robustness/bad_inputs.sh --sanitizer-report FILE
#
# prints the sanitizer report in FILE and exits 1, or exits 0 when it holds none: the check
# each case's stderr goes through, tested on real reports (tests/common/test_sanitizer_reports.cpp).
set -uo pipefail

# The first sanitizer report in a file, 12 lines from the line that opens it (AddressSanitizer,
# LeakSanitizer, UndefinedBehaviorSanitizer, UBSan's "file:line:col: runtime error:",
# ThreadSanitizer), as sanitizerReport in tests/support/test_support.cpp; nothing when none.
sanitizer_report() {
  grep -E -m 1 -A 11 -- '==[0-9]+==ERROR: [A-Za-z]*Sanitizer|: runtime error: |WARNING: ThreadSanitizer: ' "$1"
}
if [ "${1:-}" = --sanitizer-report ]; then
  report=$(sanitizer_report "${2:?usage: bad_inputs.sh --sanitizer-report FILE}") || exit 0
  printf '%s\n' "$report"
  exit 1
fi

BIN=$(cd "${1:?usage: bad_inputs.sh BIN_DIR KITTI_DIR}" && pwd)
KITTI=${2:-}
# Absolute, as BIN: the cases run in folders of their own.
[ -z "$KITTI" ] || [ ! -d "$KITTI" ] || KITTI=$(cd "$KITTI" && pwd)
MAX_SECONDS=5
MAX_KB=$((500 * 1024))
# Under AddressSanitizer (make test-sanitize sets ASAN_OPTIONS) a tool runs about twice as long
# and its shadow memory and quarantine take about three times its memory.
if [ -n "${ASAN_OPTIONS:-}" ]; then
  MAX_SECONDS=$((MAX_SECONDS * 3))
  MAX_KB=$((MAX_KB * 3))
fi
T=$(mktemp -d /tmp/msf_bad_inputs_XXXXXX)
trap 'rm -rf "$T"' EXIT

SEQ=$KITTI/odometry/sequences/04
have_kitti=0
[ -f "$SEQ/calib.txt" ] && have_kitti=1
if [ $have_kitti = 0 ] && [ "${CI:-}" = true ]; then
  echo "KITTI sample not found at '$KITTI'; CI=true requires it" >&2
  exit 1
fi
# GNU time gives each case's peak memory; without it the 500 MB limit is not checked, which
# CI=true does not accept (make deps installs it: Debian package time).
TIME=/usr/bin/time memory_note=
if [ ! -x $TIME ]; then
  if [ "${CI:-}" = true ]; then
    echo "$TIME not found; CI=true requires it to check each case's memory (apt-get install time)" >&2
    exit 1
  fi
  echo "note: $TIME not found: the cases' memory is not checked" >&2
  TIME= memory_note=" (memory not measured)"
fi

failures=0 cases=0 skipped=0 slowest=0 largest=0

# check NAME EXPECTED_EXIT PATTERN -- TOOL ARGS...
# Runs the tool in $T/run (its outputs go there); the case passes when the exit code is
# EXPECTED_EXIT, stderr (or stdout) matches PATTERN (grep -E), the run took < MAX_SECONDS
# and < MAX_KB, stderr holds no sanitizer report (an ASan build's tool that a sanitizer stops
# exits 1, as an error does), and, for an error, the run folder holds no file.
check() {
  local name=$1 expected=$2 pattern=$3
  shift 4
  local tool=$1
  shift
  cases=$((cases + 1))
  rm -rf "$T/run" && mkdir -p "$T/run"
  local start end code kb=0 ms
  start=$(date +%s%N)
  if [ -n "$TIME" ]; then
    (cd "$T/run" && timeout -s KILL $((MAX_SECONDS * 2)) $TIME -f '%M' -o "$T/mem" "$BIN/$tool" "$@" >"$T/out" 2>"$T/err")
    code=$?
    kb=$(tail -n 1 "$T/mem" 2>/dev/null | tr -dc 0-9)
    kb=${kb:-0}
  else
    (cd "$T/run" && timeout -s KILL $((MAX_SECONDS * 2)) "$BIN/$tool" "$@" >"$T/out" 2>"$T/err")
    code=$?
  fi
  end=$(date +%s%N)
  ms=$(((end - start) / 1000000))
  [ $ms -gt $slowest ] && slowest=$ms
  [ "$kb" -gt $largest ] && largest=$kb
  local why="" report
  report=$(sanitizer_report "$T/err")
  [ -z "$report" ] || why="a sanitizer report in stderr;"
  [ "$code" = "$expected" ] || why="$why exit $code, expected $expected;"
  grep -Eq -- "$pattern" "$T/err" "$T/out" || why="$why message does not match '$pattern';"
  [ $ms -lt $((MAX_SECONDS * 1000)) ] || why="$why took $ms ms;"
  [ "$kb" -lt $MAX_KB ] || why="$why used $((kb / 1024)) MB;"
  if [ "$expected" != 0 ] && [ -n "$(ls -A "$T/run")" ]; then
    why="$why left $(ls -A "$T/run" | tr '\n' ' ');"
  fi
  if [ -z "$why" ]; then
    printf 'ok    %-44s %5d ms %5d MB\n' "$name" $ms $((kb / 1024))
  else
    failures=$((failures + 1))
    printf 'FAIL  %-44s %s\n' "$name" "$why"
    if [ -n "$report" ]; then
      printf '%s\n' "$report" | sed 's/^/      | /'
    else
      sed 's/^/      | /' "$T/err" | tail -n 5
    fi
  fi
}

skip() {
  skipped=$((skipped + 1))
  printf 'skip  %-44s (no KITTI sample)\n' "$1"
}

# ---- fixtures --------------------------------------------------------------------------
F=$T/f
mkdir -p "$F"
# A small organized depth cloud (8x6, camera 60 px focal), every third pixel with a depth.
python3 - "$F" <<'EOF'
import math, sys, struct
f = sys.argv[1]
W, H = 8, 6
def pcd(path, rows, fields="x y z intensity", width=W, height=H):
    n = len(fields.split())
    with open(path, "w") as o:
        o.write("# .PCD v0.7\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\nCOUNT %s\n" % (
            fields, " ".join(["4"] * n), " ".join(["F"] * n), " ".join(["1"] * n)))
        o.write("WIDTH %d\nHEIGHT %d\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA ascii\n" % (width, height, width * height))
        for r in rows:
            o.write(" ".join(r) + "\n")
def depth_rows(z_of):
    rows = []
    for v in range(H):
        for u in range(W):
            z = z_of(u, v)
            if z is None:
                rows.append(["nan", "nan", "nan", "0"])
            else:
                rows.append(["%g" % ((u - 3.5) * z / 60), "%g" % ((v - 2.5) * z / 60), "%g" % z, "0.5"])
    return rows
pcd(f + "/sparse.pcd", depth_rows(lambda u, v: 5.0 + 0.1 * u if (u + v) % 3 == 0 else None))
pcd(f + "/dense.pcd", depth_rows(lambda u, v: 5.0 + 0.1 * u))
# The same with msf_fuse's sky_depth field, a bound of 0 at pixel (2, 1): no sky carves to there.
sky_rows = [r + ["0" if i == 1 * W + 2 else "nan"] for i, r in enumerate(depth_rows(lambda u, v: 5.0 + 0.1 * u))]
pcd(f + "/sky_zero.pcd", sky_rows, fields="x y z intensity sky_depth")
pcd(f + "/far.pcd", depth_rows(lambda u, v: 1e30 if (u, v) == (2, 2) else 5.0))
# A stereo cloud whose confidence at pixel (2, 1) is NaN.
nan_confidence = [r[:3] + ["0", "nan" if i == 1 * W + 2 else r[3]] for i, r in enumerate(depth_rows(lambda u, v: 5.0))]
pcd(f + "/nan_confidence.pcd", nan_confidence, fields="x y z rgb confidence")
def volume_pcd(path, fields, sizes, types, rows):
    """A volume .pcd of 0.1 m voxels (ASCII) with the fields given, one row a voxel."""
    open(path, "w").write("# .PCD v0.7 - Point Cloud Data file format\n"
        "# msfusion tsdf voxel_size_m 0.1 truncation_m 0.3\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes +
        "\nTYPE " + types + "\nCOUNT" + " 1" * len(fields.split()) + "\nWIDTH %d\nHEIGHT 1\n" % len(rows) +
        "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA ascii\n" % len(rows) + "".join(r + "\n" for r in rows))
volume_pcd(f + "/passes9.pcd", "x y z sdf weight rgb passes", "4 4 4 4 4 4 1", "F F F F F U U",
           ["0 0 0 -0.05 10 4278190335 1", "0.1 0 0 0.05 10 4278190335 9"])
volume_pcd(f + "/reappeared2.pcd", "x y z sdf weight rgb passes reappeared", "4 4 4 4 4 4 1 1", "F F F F F U U U",
           ["0 0 0 -0.05 10 4278190335 1 1", "0.1 0 0 0.05 10 4278190335 0 2"])
volume_pcd(f + "/noweight.pcd", "x y z sdf rgb", "4 4 4 4 4", "F F F F U",
           ["0 0 0 -0.05 4278190335", "0.1 0 0 0.05 4278190335"])
for name, second in [("offgrid", "0.05 0 0 0.05 10 4278190335"), ("nansdf", "0.1 0 0 nan 10 4278190335"),
                     ("negweight", "0.1 0 0 0.05 -1 4278190335")]:  # the second voxel at fault
    volume_pcd(f + "/" + name + ".pcd", "x y z sdf weight rgb", "4 4 4 4 4 4", "F F F F F U",
               ["0 0 0 -0.05 10 4278190335", second])
inf_rows = depth_rows(lambda u, v: 5.0)
inf_rows[3][2] = "inf"
pcd(f + "/inf.pcd", inf_rows)
pcd(f + "/allnan.pcd", depth_rows(lambda u, v: None))
pcd(f + "/wrong_fields.pcd", [["1", "2", "3"]] * (W * H), fields="a b c")
rows = depth_rows(lambda u, v: 5.0)
rows[3] = ["1", "2", "abc", "0"]
pcd(f + "/abc.pcd", rows)
# A 1.4 KB file whose header claims 1e9 points.
with open(f + "/bomb.pcd", "w") as o:
    o.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1000000000\nHEIGHT 1\n"
            "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000000000\nDATA binary\n")
    o.write("\0" * 1300)
with open(f + "/bomb.ply", "w") as o:
    o.write("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n")
    o.write("\0" * 1300)
# PCL's parser reads the count -7 as 2^64 - 7 (fuzz_cloud: it sized the cloud at ~52 GB).
with open(f + "/negative.ply", "w") as o:
    o.write("ply\nformat binary_little_endian 1.0\nelement vertex -7\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n")
    o.write("\0" * 1300)
# Coordinates written as int32 and as float64 (PCL read them as zeros), and a float64 no float holds.
def binary_pcd(path, size, type_, values, fmt):
    with open(path, "wb") as o:
        o.write(("VERSION 0.7\nFIELDS x y z\nSIZE %s %s %s\nTYPE %s %s %s\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT %d\n"
                 "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n" % (size, size, size, type_, type_, type_, W, H, W * H)).encode())
        o.write(b"".join(struct.pack("<3" + fmt, *v) for v in values))
binary_pcd(f + "/int32.pcd", 4, "I", [(u - 4, v - 3, 5 + u) for v in range(H) for u in range(W)], "i")
binary_pcd(f + "/double.pcd", 8, "F", [((u - 3.5) * 0.1, (v - 2.5) * 0.1, 5.25) for v in range(H) for u in range(W)], "d")
binary_pcd(f + "/double_huge.pcd", 8, "F", [(0, 0, 1e300 if (u, v) == (3, 2) else 5) for v in range(H) for u in range(W)], "d")
# PLY headers PCL's reader aborts on or sizes a cloud from.
xyz = "property float x\nproperty float y\nproperty float z\n"
open(f + "/blank_obj_info.ply", "w").write("ply\nformat ascii 1.0\n obj_info x\nelement vertex 1\n" + xyz + "end_header\n1 2 3\n")
open(f + "/grid.ply", "w").write("ply\nformat ascii 1.0\nobj_info num_cols 100000\nobj_info num_rows 100000\n"
                                 "element vertex 1\n" + xyz + "end_header\n1 2 3\n")
# A small scan, and one whose every reflectance is NaN.
with open(f + "/scan.bin", "wb") as o:
    o.write(b"".join(struct.pack("<4f", 5.0, 0.1 * i, 0.0, 0.5) for i in range(1000)))
with open(f + "/nan_reflectance.bin", "wb") as o:
    o.write(b"".join(struct.pack("<4f", 5.0, 0.1 * i, 0.0, float("nan")) for i in range(100)))
# A store whose index lists a tile twice (every triangle of it was doubled).
import os
os.makedirs(f + "/store/tsdf")
open(f + "/store/tsdf/index.txt", "w").write("msfusion-tsdf-store 1\nvoxel_size_m 0.1\ntruncation_m 0.3\nblock_side 8\n"
                                             "tile_blocks 4\ntiles 3\n0 0 0\n1 0 0\n0 0 0\n")
# A store whose one tile holds a voxel of NaN sdf (a file damaged or of another program).
os.makedirs(f + "/store_nan/tsdf")
open(f + "/store_nan/tsdf/index.txt", "w").write("msfusion-tsdf-store 1\nvoxel_size_m 0.1\ntruncation_m 0.3\n"
                                                 "block_side 8\ntile_blocks 4\ntiles 1\n0 0 0\n")
voxels = [struct.pack("<2f4B", float("nan") if i == 0 else 0.1, 1.0, 0, 0, 0, 0) for i in range(512)]
open(f + "/store_nan/tsdf/0_0_0.blk", "wb").write(b"MSFBLK01" + struct.pack("<2d2i", 0.1, 0.3, 8, 1) +
                                                   struct.pack("<3i4B", 0, 0, 0, 0, 0, 0, 0) + b"".join(voxels))
# A store whose index says a tile is 100000 blocks on a side.
os.makedirs(f + "/store_wide/tsdf")
open(f + "/store_wide/tsdf/index.txt", "w").write("msfusion-tsdf-store 1\nvoxel_size_m 0.1\ntruncation_m 0.3\n"
                                                  "block_side 8\ntile_blocks 100000\ntiles 1\n0 0 0\n")
# A folder where a tool's output file would go.
os.makedirs(f + "/folder.png/inside")
# A PNG whose header says 30000 x 20000 (the pixels are never read).
import zlib
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
with open(f + "/huge.png", "wb") as o:
    o.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 30000, 20000, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(b"\0" * 1000)) + chunk(b"IEND", b""))
# ... and 8192 x 2472: within 8192 a side, but a pair of them ran for minutes in gigabytes.
with open(f + "/wide.png", "wb") as o:
    o.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 8192, 2472, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(b"\0" * 1000)) + chunk(b"IEND", b""))
# Calibrations (the project's YAML): good, and each fault on its own.
def yaml(path, fx=60.0, tx1=-30.0, w=8, h=6, nan=False):
    P = lambda tx: "[ %s, 0., 3.5, %s, 0., %s, 2.5, 0., 0., 0., 1., 0. ]" % (fx, tx, fx)
    with open(path, "w") as o:
        o.write("%YAML:1.0\n---\n")
        for i, tx in enumerate([0.0, tx1, 0.0, tx1]):
            data = P(tx) if not (nan and i == 0) else P(0.0).replace("3.5", ".NaN")
            o.write("P%d: !!opencv-matrix\n   rows: 3\n   cols: 4\n   dt: d\n   data: %s\n" % (i, data))
        o.write("image_width: %d\nimage_height: %d\n" % (w, h))
        o.write("T_cam0_velo: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n"
                "   data: [ 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1. ]\n")
yaml(f + "/camera.yaml")
yaml(f + "/swapped.yaml", tx1=30.0)
yaml(f + "/camera_16x12.yaml", w=16, h=12)
yaml(f + "/nano_baseline.yaml", tx1=-60e-9)
yaml(f + "/far_baseline.yaml", tx1=-60 * 990e3)
with open(f + "/camera.yaml") as i:
    text = i.read()
open(f + "/p1_fx.yaml", "w").write(text.replace("P1: !!opencv-matrix\n   rows: 3\n   cols: 4\n   dt: d\n   data: [ 60.0,",
                                               "P1: !!opencv-matrix\n   rows: 3\n   cols: 4\n   dt: d\n   data: [ 61.0,"))
open(f + "/dt_u.yaml", "w").write(text.replace("dt: d", "dt: u", 1))
# A KITTI calib.txt whose P0 is given twice (the last won).
P = "60 0 3.5 %s 0 60 2.5 0 0 0 1 0"
open(f + "/twice.txt", "w").write("P0: %s\nP1: %s\nP2: %s\nP3: %s\nP0: %s\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n" % (
    P % 0, P % -30, P % 0, P % -30, (P % 0).replace("60", "70", 1)))
yaml(f + "/fx0.yaml", fx=0.0)
yaml(f + "/baseline0.yaml", tx1=0.0)
yaml(f + "/nan.yaml", nan=True)
yaml(f + "/huge.yaml", w=100000, h=100000)
# OpenCV 4.6's YAML parser loops forever on an indented top level (fuzz_calibration).
open(f + "/indented.yaml", "w").write("%YAML:1.0\n k: 4\na: -\n")
# Configurations that are no configuration, or a wrong one.
open(f + "/typo_section.yaml", "w").write("tsdf_volumes:\n  voxel_size_m: 0.05\n")
open(f + "/threads_wrap.yaml", "w").write("interpolation:\n  threads: 4294967297\n")
open(f + "/empty.yaml", "w").write("")
open(f + "/list.yaml", "w").write("- stereo\n- fusion\n")
open(f + "/twice.yaml", "w").write("stereo:\n  p1: 8\n  p1: 9\n")
open(f + "/deep.yaml", "w").write("stereo:\n  p1: " + "[" * 33000 + "]" * 33000 + "\n")
open(f + "/unclosed.yaml", "w").write("stereo: {p1: 8, p2: 90\nfusion:\n  method: paper\n")
open(f + "/unknown_key.yaml", "w").write("stereo:\n  block_size: 7\n")
open(f + "/wrong_type.yaml", "w").write("# a comment\nstereo: {left_right_check: maybe}\n")
open(f + "/out_of_range.yaml", "w").write("synthetic:\n  frames: 3\n  lidar_dropout: 1.5\n")
open(f + "/long_number.yaml", "w").write("stereo:\n  p1: " + "7" * 1000000 + "\n")
# Poses: one line each.
I = "1 0 0 0 0 1 0 0 0 0 1 0"
open(f + "/pose.txt", "w").write(I + "\n")
open(f + "/pose_scaled.txt", "w").write("1000 0 0 0 0 1000 0 0 0 0 1000 0\n")
open(f + "/pose_nan.txt", "w").write("1 0 0 nan 0 1 0 0 0 0 1 0\n")
open(f + "/pose_far.txt", "w").write("1 0 0 1e30 0 1 0 0 0 0 1 0\n")
open(f + "/pose_reach.txt", "w").write("1 0 0 900000 0 1 0 0 0 0 1 0\n")
# Disparity ground truth with no valid pixel, an estimate, and a small grey image.
def png(path, width, height, bits, value):
    raw = b"".join(b"\0" + (value.to_bytes(2, "big") if bits == 16 else bytes([value])) * width for _ in range(height))
    with open(path, "wb") as o:
        o.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bits, 0, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
png(f + "/gt_empty.png", W, H, 16, 0)
png(f + "/est.png", W, H, 16, 256 * 5)
png(f + "/small.png", W, H, 8, 128)
EOF
# 2 GB of holes: a scan file read whole before anything looked at it.
truncate -s 2G "$F/huge.bin"

if [ $have_kitti = 1 ]; then
  K=$T/k
  # Copies of odometry 04's calibration with one fault each.
  mkdir -p "$K/scaled_tr" "$K/p1x"
  sed -E 's/^Tr: ([^ ]+)/Tr: 1000/' "$SEQ/calib.txt" >"$K/scaled_tr/calib.txt"
  sed -E 's/^(P1: [^ ]+ [^ ]+ )[^ ]+/\11.0x/' "$SEQ/calib.txt" >"$K/p1x/calib.txt"
  # Small odometry datasets (links to the sample's files): 3 images and 4 scans; a right
  # image of the wrong size; a pose with a NaN.
  dataset() { # NAME FRAMES SCANS
    local d=$K/$1/sequences/04
    mkdir -p "$d/image_0" "$d/image_1" "$d/velodyne" "$K/$1/poses"
    ln -s "$SEQ/calib.txt" "$d/calib.txt"
    for i in $(seq 0 $(($2 - 1))); do
      n=$(printf %06d "$i")
      ln -s "$SEQ/image_0/$n.png" "$d/image_0/$n.png"
      ln -s "$SEQ/image_1/$n.png" "$d/image_1/$n.png"
    done
    for i in $(seq 0 $(($3 - 1))); do
      n=$(printf %06d "$i")
      ln -s "$SEQ/velodyne/$n.bin" "$d/velodyne/$n.bin"
    done
    head -n "$2" "$KITTI/odometry/poses/04.txt" >"$K/$1/poses/04.txt"
  }
  dataset odo 3 4
  dataset odo_small_right 2 2
  rm "$K/odo_small_right/sequences/04/image_1/000000.png"
  cp "$F/small.png" "$K/odo_small_right/sequences/04/image_1/000000.png"
  dataset odo_nan 2 2
  sed -i -E '2s/^([^ ]+ [^ ]+ [^ ]+ )[^ ]+/\1nan/' "$K/odo_nan/poses/04.txt"
  cp "$F/small.png" "$K/small.png"
  dataset odo_empty_scan 2 2
  rm "$K/odo_empty_scan/sequences/04/velodyne/000000.bin"
  : >"$K/odo_empty_scan/sequences/04/velodyne/000000.bin"
  dataset odo_missing_color 2 2
  mkdir -p "$K/odo_missing_color/sequences/04/image_2"
  ln -s "$SEQ/image_2/000001.png" "$K/odo_missing_color/sequences/04/image_2/000001.png"
  # Files beside the frames that are not frames; a frame (000012) beyond the 3 poses.
  dataset odo_stray 2 2
  echo "not an image" >"$K/odo_stray/sequences/04/image_0/.DS_Store"
  echo "frames of drive 04" >"$K/odo_stray/sequences/04/image_0/README"
  echo "not a scan" >"$K/odo_stray/sequences/04/velodyne/.DS_Store"
  dataset odo_beyond_poses 3 3
  for c in image_0 image_1; do ln -s "$SEQ/$c/000002.png" "$K/odo_beyond_poses/sequences/04/$c/000012.png"; done
  ln -s "$SEQ/velodyne/000002.bin" "$K/odo_beyond_poses/sequences/04/velodyne/000012.bin"
  # A times.txt whose third time goes back.
  dataset odo_times_back 3 3
  printf '0.0\n0.1\n0.05\n' >"$K/odo_times_back/sequences/04/times.txt"
fi

# ---- limits checked before allocating ---------------------------------------------------
check "interpolate -threads 100000" 1 "interpolation.threads must be in 0..256, not 100000" -- \
  msf_interpolate "$F/sparse.pcd" o.pcd -threads 100000
check "interpolate -threads -1" 1 "threads.*not -1" -- msf_interpolate "$F/sparse.pcd" o.pcd -threads -1
check "interpolate -canvas of an organized cloud" 1 "-canvas needs a scan: '.*sparse.pcd' is an organized cloud" -- \
  msf_interpolate "$F/sparse.pcd" o.pcd -canvas
check "info: POINTS 1e9 in a 1.4 KB .pcd" 1 "declares 1000000000 points" -- msf_info "$F/bomb.pcd"
check "interpolate: POINTS 1e9 in a 1.4 KB .pcd" 1 "bomb.pcd' declares 1000000000 points" -- \
  msf_interpolate "$F/bomb.pcd" o.pcd
check "info: element vertex 1e9 in a .ply" 1 "declares 1000000000 vertex" -- msf_info "$F/bomb.ply"
check "info: element vertex -7 in a .ply" 1 "negative.ply' is not a valid .ply file \(bad header\): line 3 'element vertex -7': count '-7' is not a whole number" -- \
  msf_info "$F/negative.ply"
check "info: a point at z = inf is not valid" 0 "valid: +47 \(97.9 %\)" -- msf_info "$F/inf.pcd"
check "integrate -voxel 1e-6" 1 "voxel_size_m \(-voxel, the voxel size\) must be 0.001 .. 10 m, got 1e-06" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -voxel 1e-6
check "integrate -trunc 1e6" 1 "truncation_m \(-trunc\) must be > 0 and at most 64 voxels" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -trunc 1e6
check "integrate -sweeps 1000000" 1 "tsdf_integrator.sweeps must be in 0..100, not 1000000" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -sweeps 1000000
check "integrate: a sky_depth bound of 0" 1 "sky_zero.pcd': field 'sky_depth' at pixel \(2, 1\) is 0\.0+: a pixel's bound" -- \
  msf_integrate "$F/sky_zero.pcd" -poses "$F/pose.txt" -o v.pcd
check "integrate: rotation scaled by 1000" 1 "pose_scaled.txt' line 1 is not a rigid transform" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose_scaled.txt" -o v.pcd
check "integrate: translation 1e30" 1 "pose_far.txt' line 1 has a translation of 1e\+30 m" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose_far.txt" -o v.pcd
check "integrate: pose beyond the volume's reach" 1 "beyond the volume's .* m at 0.001" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose_reach.txt" -o v.pcd -voxel 0.001 -trunc 0.003
check "integrate -max_memory 1" 1 "over its memory budget of 1 MiB" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -max_memory 1 -voxel 0.001 -trunc 0.05
check "lambda_study -voxel 1e-6" 1 "lambda_study.voxel_size_m must be in 0.001..10, not 1.0e-06" -- msf_lambda_study -o out -voxel 1e-6
check "lambda_study -sweeps 1000000" 1 "lambda_study.sweeps must be in 0..100" -- msf_lambda_study -o out -sweeps 1000000
printf 'image_width: 640\nimage_height: 480\nleft: {fx: 500.0, fy: 500.0, cx: 320.0, cy: 240.0}\nbaseline_m: 0.12\nlidar:\n  T_cam_lidar: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n  rings: 32\n' >"$F/rings_only.yaml"
check "synth -rig: rings without their elevations" 1 "rings_only.yaml': lidar.rings 32 without lidar.beam_elevations_deg" -- \
  msf_synth -o out -frames 1 -rig "$F/rings_only.yaml"
printf 'image_width: 640\nimage_height: 480\nleft: {fx: 500.0, fy: 500.0, cx: 320.0, cy: 240.0}\nbaseline_m: 0.12\nlidar:\n  T_cam_lidar: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n  beam_elevation_deg: [-2, 2]\n' >"$F/rig_misspelt_key.yaml"
check "synth -rig: a misspelt key" 1 "rig_misspelt_key.yaml' line 7: 'beam_elevation_deg' is not a key of lidar" -- \
  msf_synth -o out -frames 1 -rig "$F/rig_misspelt_key.yaml"
printf 'imagewidth: 640\nimageheight: 480\nleftcam: {fx: 500.0, fy: 500.0, cx: 320.0, cy: 240.0}\n' >"$F/rig_all_misspelt.yaml"
check "synth -rig: every key misspelt" 1 "rig_all_misspelt.yaml' line 1: 'imagewidth' is not a key of a rig file" -- \
  msf_synth -o out -frames 1 -rig "$F/rig_all_misspelt.yaml"
printf 'image_height: 480\nleft: {fx: 500.0, fy: 500.0, cx: 320.0, cy: 240.0}\nbaseline_m: 0.12\n' >"$F/rig_no_width.yaml"
check "synth -rig: image_width missing" 1 "rig_no_width.yaml': image_width is missing" -- \
  msf_synth -o out -frames 1 -rig "$F/rig_no_width.yaml"
check "synth -lidar hdl16" 1 "synthetic.lidar_model must be hdl64e \| hdl32e \| beams, not 'hdl16'" -- \
  msf_synth -o out -frames 1 -lidar hdl16
check "synth -lidar beams without beams" 1 "synthetic.lidar_beam_elevations_deg must hold 1..1024 elevations for lidar_model beams, not 0" -- \
  msf_synth -o out -frames 1 -lidar beams
check "synth -camera kitti -focal 500" 1 "option -focal sets a pinhole camera, but -camera is 'kitti'" -- \
  msf_synth -o out -frames 1 -camera kitti -focal 500
check "synth -baseline 0" 1 "synthetic.baseline_m must be in \(0, 10\], not 0.0" -- msf_synth -o out -frames 1 -baseline 0
check "synth -sky foo" 1 "option -sky: unknown sky 'foo' \(known: pale, kitti\)" -- msf_synth -o out -frames 1 -sky foo
printf 'synthetic:\n  sky: cloudy\n' >"$F/sky_cloudy.yaml"
check "synth -config: an unknown sky" 1 "sky_cloudy.yaml' line 2: synthetic.sky must be pale \| kitti, not 'cloudy'" -- \
  msf_synth -o out -frames 1 -config "$F/sky_cloudy.yaml"
printf 'accumulation:\n  scans: 40\n' >"$F/scans_40.yaml"
check "interpolate -config: 40 earlier scans" 1 "scans_40.yaml' line 2: accumulation.scans must be a whole number in 0..16, not 40" -- \
  msf_interpolate "$F/sparse.pcd" o.pcd -config "$F/scans_40.yaml"
printf 'fusion:\n  hole_fill_px: -1\n' >"$F/fill_negative.yaml"
check "fuse -config: a negative hole fill" 1 "fill_negative.yaml' line 2: fusion.hole_fill_px must be a whole number in 0..2147483647, not -1" -- \
  msf_fuse "$F/dense.pcd" "$F/dense.pcd" o.pcd -calib "$F/camera.yaml" -config "$F/fill_negative.yaml"
printf 'map_prior:\n  min_depth_m: 50\n' >"$F/prior_inverted.yaml"
check "mesh -config: the map prior's rays end before they start" 1 \
  "prior_inverted.yaml': map_prior.max_depth_m \(40.000000\) must exceed min_depth_m \(50.000000\)" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/prior_inverted.yaml"

# ---- configuration files ------------------------------------------------------------------
check "mesh -config: a misspelt section" 1 "typo_section.yaml' line 1: 'tsdf_volumes' is not a section of the configuration" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/typo_section.yaml"
check "interpolate -config: threads 4294967297" 1 "threads_wrap.yaml' line 2: interpolation.threads must be a whole number in 0..256, not 4294967297" -- \
  msf_interpolate "$F/sparse.pcd" o.pcd -config "$F/threads_wrap.yaml"
check "mesh -config: an empty file" 1 "config '.*empty.yaml' is empty" -- msf_mesh "$F/dense.pcd" o.ply -config "$F/empty.yaml"
check "mesh -config: a list" 1 "list.yaml' line 1: a config file is a map of sections" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/list.yaml"
check "mesh -config: a key twice" 1 "twice.yaml' line 3: 'stereo.p1' appears twice \(lines 2 and 3\)" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/twice.yaml"
check "mesh -config: nested 33000 levels" 1 "deep.yaml' is not valid YAML: line .* levels deep \(yaml-cpp's limit\)" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/deep.yaml"
check "synth -config: malformed YAML" 1 "unclosed.yaml' is not valid YAML: line [0-9]+, column [0-9]+: " -- \
  msf_synth -o out -config "$F/unclosed.yaml"
check "synth -config: an unknown key" 1 "unknown_key.yaml' line 2: 'stereo.block_size' is not a key of section 'stereo' \(its keys: engine, mode" -- \
  msf_synth -o out -config "$F/unknown_key.yaml"
check "synth -config: a wrong type" 1 "wrong_type.yaml' line 2: stereo.left_right_check must be true or false, not 'maybe'" -- \
  msf_synth -o out -config "$F/wrong_type.yaml"
check "synth -config: a value out of range" 1 "out_of_range.yaml' line 3: synthetic.lidar_dropout must be a finite number in \[0, 1\), not 1.5" -- \
  msf_synth -o out -config "$F/out_of_range.yaml"
check "synth -config: a key twice" 1 "twice.yaml' line 3: 'stereo.p1' appears twice" -- \
  msf_synth -o out -config "$F/twice.yaml"
check "mesh -config: a number of a million digits" 1 "long_number.yaml' line 2: stereo.p1 must be a whole number in 0..2147483647, not 7777.*\(1000000 characters\)" -- \
  msf_mesh "$F/dense.pcd" o.ply -config "$F/long_number.yaml"
check "mesh: passes beyond what a voxel counts" 1 "marching_cubes.component_release_passes must be in 0..3, not 4" -- \
  msf_mesh "$F/dense.pcd" o.ply -component_release_passes 4
check "mesh: a volume whose voxel has more passes than a voxel counts" 1 "passes9.pcd': voxel 1 has passes 9, more than the 3 a voxel counts" -- \
  msf_mesh "$F/passes9.pcd" o.ply
check "mesh: a voxel's reappeared not 0 or 1" 1 "reappeared2.pcd': voxel 1 has reappeared 2, not 0 or 1" -- \
  msf_mesh "$F/reappeared2.pcd" o.ply
check "mesh: a volume without the weight field" 1 "noweight.pcd' has no field 'weight'" -- \
  msf_mesh "$F/noweight.pcd" o.ply
check "mesh: a voxel off the volume's grid" 1 "offgrid.pcd': voxel 1 at \(0.05, 0, 0\) is not on the 0.1 m grid" -- \
  msf_mesh "$F/offgrid.pcd" o.ply
check "mesh: a voxel's sdf not a number" 1 "nansdf.pcd': voxel 1 has a coordinate, sdf or weight that is not a finite" -- \
  msf_mesh "$F/nansdf.pcd" o.ply
check "mesh: a voxel of negative weight" 1 "negweight.pcd': voxel 1 has a negative weight \(-1\)" -- \
  msf_mesh "$F/negweight.pcd" o.ply
check "pcd2png -disparity, fx 0" 1 "fx0.yaml': P0 has fx 0" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/fx0.yaml"
check "pcd2png -disparity, NaN in P0" 1 "nan.yaml': P0 has a value that is not finite" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/nan.yaml"
check "pcd2png -disparity, baseline 0" 1 "baseline0.yaml': the grey pair's focal length x baseline is 0" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/baseline0.yaml"
check "pcd2png -calib with an indented top level" 1 "indented.yaml' is not valid YAML: line 2: the top level is indented" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/indented.yaml"
check "pcd2png: a depth of 1e30 m saturates, said" 0 "1 pixel of the depth beyond the format.s largest value \(255.996\) saturate" -- \
  msf_pcd2png "$F/far.pcd" d.png
check "stereo: 30000x20000 PNG header" 1 "huge.png': image size 30000x20000 is outside 1x1 .. 8192x8192" -- \
  msf_stereo "$F/huge.png" "$F/huge.png" o.pcd -calib "$F/camera.yaml"
check "stereo: an 8192x2472 pair" 1 "wide.png': image size 8192x2472 has 20250624 pixels, more than the 16777216 \(4096x4096\)" -- \
  msf_stereo "$F/wide.png" "$F/wide.png" o.pcd -calib "$F/camera.yaml"
check "project -image_size 8192x8192" 1 "the image size given: image size 8192x8192 has 67108864 pixels, more than the 16777216" -- \
  msf_project "$F/scan.bin" o.pcd -calib "$F/camera.yaml" -image_size 8192x8192
check "interpolate: empty (all-NaN) cloud" 1 "allnan.pcd' lands in the image: the cloud has no finite point" -- \
  msf_interpolate "$F/allnan.pcd" o.pcd -calib "$F/camera.yaml"
check "interpolate: empty cloud, no calibration" 1 "too few valid points \(0\)" -- msf_interpolate "$F/allnan.pcd" o.pcd
check "info: '1 2 abc' in an ASCII .pcd" 1 "value 'abc' on data line 4 is not a number" -- msf_info "$F/abc.pcd"
check "fuse: a LiDAR depth of 1e30 m" 1 "LiDAR cloud has a depth of 1000000015.*at pixel \(2, 2\)|LiDAR cloud has a depth of 1.*e\+30|LiDAR cloud has a depth of [0-9]{20,}" -- \
  msf_fuse "$F/far.pcd" "$F/dense.pcd" o.pcd -calib "$F/camera.yaml"
check "fuse: clouds of another size than the rig's images" 1 "stereo cloud is 8x6 but calibration '.*camera_16x12.yaml' is 16x12" -- \
  msf_fuse "$F/dense.pcd" "$F/dense.pcd" o.pcd -calib "$F/camera_16x12.yaml"
check "fuse: a stereo confidence of NaN" 1 "stereo cloud's confidence at pixel \(2, 1\) is nan" -- \
  msf_fuse "$F/dense.pcd" "$F/nan_confidence.pcd" o.pcd -calib "$F/camera.yaml"
check "eval_disparity: ground truth with no valid pixel" 1 "gt_empty.png' has no valid pixel" -- \
  msf_eval_disparity "$F/gt_empty.png" "$F/est.png"

# ---- nothing silently wrong, messages that name the fault --------------------------------
check "interpolate -threads 4294967297" 1 "-threads must be a whole number in -2147483648 .. 2147483647, not '4294967297'" -- \
  msf_interpolate "$F/sparse.pcd" o.pcd -threads 4294967297
# One argument may hold 128 KB (Linux's MAX_ARG_STRLEN): 100000 digits, named by their length.
check "integrate -sweeps of 100000 digits" 1 "-sweeps must be a whole number in .*, not '9{24}\.\.\.' \(100000 characters\)" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -sweeps "$(printf '9%.0s' $(seq 100000))"
check "integrate -voxel 1e999" 1 "-voxel needs a finite number within the range of a double, not '1e999'" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -voxel 1e999
# An option given twice, or two names of one setting, with two values: neither is guessed.
check "integrate -voxel given twice" 1 "option '-voxel' is given twice, '0.1' and '0.2': give it once" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -voxel 0.1 -voxel 0.2
check "fuse -calib and -rig of two files" 1 "options '-calib' and '-rig' set one thing, given '.*camera.yaml' and 'rig.yaml': give one of them" -- \
  msf_fuse "$F/dense.pcd" "$F/dense.pcd" o.pcd -calib "$F/camera.yaml" -rig rig.yaml
check "integrate -lambda 1e300" 1 "tsdf_integrator.lambda \(-lambda\) must be 0 .. 1e6 \(beyond, eq. 7 flattens" -- \
  msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o v.pcd -lambda 1e300
check "info: x y z as int32" 0 "valid: +48 \(100.0 %\)" -- msf_info "$F/int32.pcd"
check "pcd2png: x y z as float64" 0 "\[done, [0-9.]+ ms : 48 points\]" -- msf_pcd2png "$F/double.pcd" d.png
check "info: a float64 no float32 holds" 1 "double_huge.pcd': field 'z' \(float64\) of point 19 is 1e\+300, which float32 cannot hold" -- \
  msf_info "$F/double_huge.pcd"
check "info: ' obj_info x' in a .ply header" 1 "blank_obj_info.ply' is not a valid .ply file \(bad header\): line 3 ' obj_info x': a line that starts with a blank" -- \
  msf_info "$F/blank_obj_info.ply"
check "info: obj_info 100000 x 100000 in a .ply" 1 "obj_info num_cols 100000 x num_rows 100000 make 10000000000 points, not its 1 vertices" -- \
  msf_info "$F/grid.ply"
check "pcd2png -calib with P0 twice" 1 "twice.txt': key 'P0' is given twice, on lines 1 and 5" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/twice.txt"
check "pcd2png -calib, images swapped" 1 "swapped.yaml': camera 1 is 0.5 m left of camera 0" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/swapped.yaml"
check "pcd2png -calib, baseline 1e-9 m" 1 "nano_baseline.yaml': the grey pair's baseline is 1e-09 m, outside 0.001 .. 10 m" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/nano_baseline.yaml"
check "pcd2png -calib, baseline 990 km" 1 "far_baseline.yaml': the grey pair's baseline is 990000 m, outside 0.001 .. 10 m" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/far_baseline.yaml"
check "pcd2png -calib, P1's fx not P0's" 1 "p1_fx.yaml': P1's fx 61 is not P0's 60: the cameras of a rectified pair" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/p1_fx.yaml"
check "pcd2png -calib, a matrix of dt u" 1 "dt_u.yaml': key 'P0' has dt 'u', not d \(float64\) or f \(float32\)" -- \
  msf_pcd2png "$F/dense.pcd" d.png -disparity -calib "$F/dt_u.yaml"
check "mesh: a store index listing a tile twice" 1 "index.txt' lists tile 0_0_0 twice \(tiles 1 and 3\)" -- \
  msf_mesh "$F/store" m.ply
check "mesh: a store tile with a voxel of NaN sdf" 1 "0_0_0.blk': block 1 of 1 has voxel 0 of sdf nan, not within the truncation 0.3 m" -- \
  msf_mesh "$F/store_nan" m.ply
check "mesh: a store index of 100000-block tiles" 1 "index.txt' has tile_blocks 100000, outside 1..64" -- \
  msf_mesh "$F/store_wide" m.ply
check "project: a 2 GB sparse scan file" 1 "huge.bin' has 134217728 records \(2147483648 bytes\), more than the 16777216 a scan may hold" -- \
  msf_project "$F/huge.bin" o.pcd -calib "$F/camera.yaml"
check "project: NaN reflectance everywhere" 1 "nan_reflectance.bin': each of its 100 records has a value that is not finite" -- \
  msf_project "$F/nan_reflectance.bin" o.pcd -calib "$F/camera.yaml"
check "pcd2png: the output is a folder" 1 "output '.*folder.png' is a folder, not a file" -- \
  msf_pcd2png "$F/dense.pcd" "$F/folder.png"
# Every tool, the ROS node among them, prints its version and commit (README.md says so).
for tool in "$BIN"/msf_*; do
  tool=$(basename "$tool")
  check "$tool --version" 0 "^$tool \(msfusion\) [0-9]+\.[0-9]+\.[0-9]+, commit ([0-9a-f]{12}(-dirty)?|unknown)$" -- \
    "$tool" --version
done

# ---- every write checked to the end: a full disk -----------------------------------------
# A small tmpfs, filled: each writer meets ENOSPC at its first block. Mounting needs root, as CI
# runs; elsewhere the cases are skipped, saying so.
FULL=$T/full
mkdir -p "$FULL"
if mount -t tmpfs -o size=64k tmpfs "$FULL" 2>/dev/null; then
  trap 'umount "$FULL" 2>/dev/null; rm -rf "$T"' EXIT
  head -c 1000000 /dev/zero >"$FULL/.filler" 2>/dev/null
  "$BIN/msf_integrate" "$F/dense.pcd" -poses "$F/pose.txt" -o "$F/volume.pcd" -voxel 0.05 >/dev/null 2>&1
  for ext in ply obj vtk; do
    check "mesh -> .$ext on a full disk" 1 "cannot write '$FULL/m.$ext': No space left on device" -- \
      msf_mesh "$F/volume.pcd" "$FULL/m.$ext"
  done
  check "pcd2png on a full disk" 1 "cannot write '$FULL/d.png': No space left on device" -- \
    msf_pcd2png "$F/dense.pcd" "$FULL/d.png"
  check "kitti2pcd -ascii on a full disk" 1 "cannot write '$FULL/s.pcd': No space left on device" -- \
    msf_kitti2pcd "$F/scan.bin" "$FULL/s.pcd" -ascii
  if [ $have_kitti = 1 ]; then
    check "odometry -o on a full disk" 1 "cannot write '$FULL/poses.txt': No space left on device" -- \
      msf_odometry "$SEQ" -frames 0:1 -o "$FULL/poses.txt"
  else
    skip "odometry-full-disk"
  fi
  if [ -n "$(ls -A "$FULL" | grep -v -x .filler)" ]; then
    failures=$((failures + 1))
    echo "FAIL  full disk: a truncated file was left: $(ls -A "$FULL" | grep -v -x .filler | tr '\n' ' ')"
  fi
  umount "$FULL"
elif [ "${CI:-}" = true ]; then
  echo "FAIL  full disk: cannot mount a small tmpfs at $FULL (CI=true runs as root and requires it)"
  failures=$((failures + 1))
else
  for c in mesh-ply-full mesh-obj-full mesh-vtk-full pcd2png-full kitti2pcd-ascii-full odometry-full; do
    skipped=$((skipped + 1))
    printf 'skip  %-44s (cannot mount a tmpfs: not root)\n' "$c"
  done
fi

# ---- many drives, one map (msf_batch, msf_merge, msf_eval_mesh; msf_synth's shared street) --
check "batch: no place to run the tasks" 1 "say where the tasks run, once: -slurm .* -local N" -- \
  msf_batch -o out "$F"
check "batch -run before a plan" 1 "batch plan '.*out/plan.txt' does not exist" -- msf_batch -o out -run drive:0
check "batch -run a task of no kind" 1 "task 'drives:1' is not drive:N, merge:N, mesh:N or finish" -- \
  msf_batch -o "$F" -run drives:1
check "batch: a folder that holds no drive" 1 "dataset '.*' holds no drive" -- msf_batch -o out -local 1 "$F"
check "batch: a file that is no bag" 1 "dataset '.*dense.pcd' is a file and not a ROS bag" -- \
  msf_batch -o out -local 1 "$F/dense.pcd"
printf '%s\n' "$F/dense.pcd" >"$F/drives.txt"
check "batch -list with a line that is no drive" 1 "drive list '.*drives.txt' line 1: '.*dense.pcd' is not a drive" -- \
  msf_batch -o out -local 1 -list "$F/drives.txt"
check "merge: a folder without a store" 1 "TSDF store index '.*/tsdf/index.txt' does not exist" -- \
  msf_merge -o map "$F" "$F"
check "synth -reverse off the street's start" 1 "synthetic.start_m' = 3.* leaves the street's start" -- \
  msf_synth -o out -frames 10 -start_m 3 -reverse
check "synth -street_m shorter than the drive" 1 "synthetic.street_length_m' = 5.* is shorter than the drive" -- \
  msf_synth -o out -frames 20 -street_m 5

# ---- the ROS node's command line (built with ROS 1), before any master is reached ---------
if [ -x "$BIN/msf_ros_node" ]; then
  check "ros_node: an argument that is not ROS's" 1 \
    "unexpected argument '-frames': the node takes -h, --version, remappings \\(topic:=name\\) and parameters" -- \
    msf_ros_node -frames 0:9
  check "ros_node -h: every parameter, no master" 0 "overwrite = false" -- msf_ros_node -h
else
  for c in "ros_node: an argument that is not ROS's" "ros_node -h: every parameter, no master"; do
    skipped=$((skipped + 1))
    printf 'skip  %-44s (built without ROS 1)\n' "$c"
  done
fi

# ---- cases on the KITTI sample ---------------------------------------------------------------
if [ $have_kitti = 1 ]; then
  SCAN=$SEQ/velodyne/000000.bin
  L=$SEQ/image_0/000000.png R=$SEQ/image_1/000000.png
  check "project: 100000x100000 calibration" 1 "huge.yaml': keys 'image_width' and 'image_height': image size 100000x100000" -- \
    msf_project "$SCAN" o.pcd -calib "$F/huge.yaml"
  check "interpolate: scan with a scaled rotation in Tr" 1 "LiDAR-to-camera transform is not a rigid transform" -- \
    msf_interpolate "$SCAN" o.pcd -calib "$K/scaled_tr/calib.txt"
  check "stereo -num_disparities 1232" 1 "-num_disparities 1232.*as wide as the images" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -num_disparities 1232
  check "stereo -prior without x y z" 1 "-prior '.*wrong_fields.pcd' has no field 'x'" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -prior "$F/wrong_fields.pcd"
  check "stereo -prior neither the image's size nor its canvas" 1 "-prior '.*sparse.pcd' is [0-9]+x[0-9]+: neither the image's [0-9]+x[0-9]+ nor that image with a margin" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -prior "$F/sparse.pcd"
  head -n 1 "$KITTI/odometry/poses/04.txt" >"$F/one_pose.txt"
  check "integrate -calib: a cloud neither the image's size nor its canvas" 1 "cloud '.*sparse.pcd' is [0-9]+x[0-9]+: neither the image's [0-9]+x[0-9]+ nor that image with a margin" -- \
    msf_integrate "$F/sparse.pcd" -poses "$F/one_pose.txt" -calib "$SEQ/calib.txt" -o o.pcd
  check "stereo -color of the wrong size" 1 "colour image is 8x6 but calibration" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -color "$K/small.png"
  printf '%%YAML:1.0\nrig:\n  stereo_min_disparity_px: -1.0\n' >"$F/rig_negative.yaml"
  check "stereo -config: rig.stereo_min_disparity_px -1" 1 "rig_negative.yaml. line 3: rig.stereo_min_disparity_px must be a finite number in 0..1000, not -1.0" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -config "$F/rig_negative.yaml"
  printf '%%YAML:1.0\nrig:\n  scale_ring_row: false\n' >"$F/rig_misspelt.yaml"
  check "interpolate -config: rig.scale_ring_row (misspelt)" 1 "scale_ring_row" -- \
    msf_interpolate "$SCAN" o.pcd -calib "$SEQ/calib.txt" -config "$F/rig_misspelt.yaml"
  check "P1 holds '1.0x'" 1 "key 'P1' has a value that is not a number: '1.0x'" -- \
    msf_project "$SCAN" o.pcd -calib "$K/p1x/calib.txt"
  check "reconstruct -frames 0:100000" 1 "frame range 0:100000 goes beyond the last frame" -- \
    msf_reconstruct "$SEQ" -frames 0:100000 -panels 0 -o out
  check "reconstruct -panels -1" 1 "-panels must be 0..100, not -1" -- msf_reconstruct "$SEQ" -panels -1 -o out
  check "reconstruct -sweeping_scans maybe" 1 "-sweeping_scans must be true or false, not 'maybe'" -- \
    msf_reconstruct "$SEQ" -sweeping_scans maybe -o out
  check "reconstruct: a bag's option for a folder" 1 "bag topics and frames are for a ROS bag" -- \
    msf_reconstruct "$SEQ" -sweeping_scans false -o out
  check "reconstruct -voxel 1e6" 1 "voxel_size_m \(-voxel, the voxel size\) must be 0.001 .. 10 m, got 1000000" -- \
    msf_reconstruct "$SEQ" -voxel 1e6 -o out
  check "reconstruct -max_memory 1" 1 "the run is predicted to need up to [0-9]+ MiB at its peak in memory and [0-9]+ MiB streamed .* over the memory budget of 1 MiB" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -max_memory 1 -o out
  # A budget the run would fit only streamed, for a run that needs the whole map in memory.
  check "reconstruct -compare_sources -max_memory 300" 1 "over the memory budget of 300 MiB .*, and the run needs the whole map in memory \(-compare_sources\)" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -compare_sources -max_memory 300 -o out
  # Estimated poses: nothing to predict from; the volume stops the run at its first growth.
  check "reconstruct -max_memory 1 -poses estimate" 1 "the TSDF volume needs .* over its memory budget of 1 MiB" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -max_memory 1 -poses estimate -o out
  # Millimetre voxels to 44 m: too many block columns to list; the views' boxes are counted.
  printf '%%YAML:1.0\ntsdf_volume:\n  voxel_size_m: 0.001\n  truncation_m: 0.003\n' >"$F/mm_voxels.yaml"
  check "reconstruct: 1 mm voxels, -max_memory 1000" 1 "predicted to need up to [0-9]+ MiB .* over the memory budget of 1000 MiB" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -config "$F/mm_voxels.yaml" -max_memory 1000 -o out
  check "reconstruct -config with an indented top level" 1 "config '.*indented.yaml' is not valid YAML: line 3, column 4" -- \
    msf_reconstruct "$SEQ" -config "$F/indented.yaml" -o out
  check "reconstruct -voxel 1e-6" 1 "voxel_size_m \(-voxel, the voxel size\) must be" -- msf_reconstruct "$SEQ" -voxel 1e-6 -o out
  check "reconstruct: 3 images and 4 scans" 1 "has 3 images in camera 0's folder but 4 .bin files" -- \
    msf_reconstruct "$K/odo/sequences/04" -o out
  check "reconstruct: right image of the wrong size" 1 "image '.*image_1/000000.png' is 8x6, not the calibration's" -- \
    msf_reconstruct "$K/odo_small_right/sequences/04" -frames 0:0 -panels 0 -o out
  check "reconstruct: an empty scan" 1 "frame 000000: scan '.*velodyne/000000.bin' has no finite point" -- \
    msf_reconstruct "$K/odo_empty_scan/sequences/04" -panels 0 -o out
  check "reconstruct: a missing colour image" 1 "frame 000000: colour image '.*image_2/000000.png' is missing" -- \
    msf_reconstruct "$K/odo_missing_color/sequences/04" -panels 0 -o out
  check "reconstruct -poses refined (a typo)" 1 "-poses 'refined': no such file, and not one of dataset, refine" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -poses refined -o out
  mkdir -p "$K/no_poses/sequences/04"
  for f in calib.txt times.txt image_0 image_1 image_2 velodyne; do ln -s "$SEQ/$f" "$K/no_poses/sequences/04/$f"; done
  check "reconstruct -poses refine without poses" 1 "-poses refine: '.*no_poses/sequences/04' has no poses" -- \
    msf_reconstruct "$K/no_poses/sequences/04" -frames 0:0 -panels 0 -poses refine -o out
  check "odometry: .DS_Store and a README in image_0" 0 "Saving .*p.txt" -- \
    msf_odometry "$K/odo_stray/sequences/04" -o p.txt
  check "odometry: a frame beyond the poses" 1 "frame 000012 has no entry in poses '.*04.txt', which has 3 \(frames 0..2\)" -- \
    msf_odometry "$K/odo_beyond_poses/sequences/04" -o p.txt
  # The evaluation tools: a trajectory or a method that cannot be scored is named with its fault.
  P5=$K/poses5
  mkdir -p "$P5"
  head -n 5 "$KITTI/odometry/poses/04.txt" >"$P5/five.txt"
  head -n 3 "$P5/five.txt" >"$P5/three.txt"
  printf '1 0 0 0 0 1 0 0 0 0 1\n' >"$P5/eleven.txt"
  sed '3s/^[^ ]*/2/' "$P5/five.txt" >"$P5/stretched.txt"
  check "eval_odometry: 3 poses against 5" 1 "three.txt' has 3 poses and '.*five.txt' 5 \(use -frames a:b" -- \
    msf_eval_odometry "$P5/three.txt" "$P5/five.txt"
  check "eval_odometry: a line of 11 numbers" 1 "poses '.*eleven.txt' line 1: expected 12 numbers \(a 3x4 row-major matrix\), got 11" -- \
    msf_eval_odometry "$P5/eleven.txt" "$P5/five.txt"
  check "eval_odometry: a pose that is not rigid" 1 "stretched.txt' line 3 is not a rigid transform: its rotation is not orthonormal" -- \
    msf_eval_odometry "$P5/stretched.txt" "$P5/five.txt"
  check "holdout -methods with a typo" 1 "unknown method 'fussed'; known methods: interpolated," -- \
    msf_holdout "$SEQ" -frames 0:0 -methods fused,fussed
  check "holdout -csv into a missing folder" 1 "cannot write '/nonexistent/h.csv': output folder '/nonexistent' does not exist" -- \
    msf_holdout "$SEQ" -frames 0:0 -methods interpolated -csv /nonexistent/h.csv
  if [ -x "$BIN/msf_kitti2bag" ]; then # a build with the ROS module
    check "kitti2bag -images webp, before any frame" 1 "msf_kitti2bag: error: the bag's images must be raw, png or jpeg, not 'webp'" -- \
      msf_kitti2bag "$SEQ" -frames 0:0 -images webp -o b.bag
    if grep -q Writing "$T/out"; then
      failures=$((failures + 1))
      echo "FAIL  kitti2bag -images webp began writing before it refused the codec"
    fi
  fi
  check "odometry -o into a missing folder, before tracking" 1 \
    "cannot write '/nonexistent/p.txt': output folder '/nonexistent' does not exist" -- \
    msf_odometry "$SEQ" -frames 0:1 -o /nonexistent/p.txt
  if grep -q Tracking "$T/out"; then
    failures=$((failures + 1))
    echo "FAIL  odometry -o into a missing folder tracked the frames first"
  fi
  check "reconstruct: a time that goes back" 1 "times.txt' line 3 '0.05' does not follow line 2's: the times must increase" -- \
    msf_reconstruct "$K/odo_times_back/sequences/04" -panels 0 -o out
  check "reconstruct: NaN in a pose" 1 "poses '.*04.txt' line 2: value 4 'nan' is not finite" -- \
    msf_reconstruct "$K/odo_nan/sequences/04" -o out
  # kitti2pcd -input_dir: a truncated scan among good ones converts nothing.
  mkdir -p "$K/scans" "$K/pcds"
  ln -s "$SEQ/velodyne/000000.bin" "$K/scans/000000.bin"
  head -c 1000 "$SEQ/velodyne/000001.bin" >"$K/scans/000001.bin"
  check "kitti2pcd -input_dir with a truncated scan" 1 "000001.bin' has 1000 bytes.*nothing was converted" -- \
    msf_kitti2pcd -input_dir "$K/scans" -output_dir "$K/pcds"
  if [ -n "$(ls -A "$K/pcds")" ]; then
    failures=$((failures + 1))
    echo "FAIL  kitti2pcd -input_dir left $(ls "$K/pcds")"
  fi
  # reconstruct: a run killed in OUT leaves OUT as it was; the next run removes its staging.
  # An earlier output is a folder whose manifest lists its files (msf::OutputFolder).
  mkdir -p "$T/killed/out"
  echo '{"previous": true}' >"$T/killed/out/summary.json"
  printf '# msfusion output of msf_reconstruct\nsummary.json\n' >"$T/killed/out/.msf_manifest"
  mkdir "$T/killed/.out.partial.999999999.0" && touch "$T/killed/.out.partial.999999999.0/.msf_staging" \
    "$T/killed/.out.partial.999999999.0/.mesh.tmp1.ply"
  mkdir -p "$T/foreign" && touch "$T/foreign/notes.odt"
  check "reconstruct: existing OUT with a foreign file" 1 "holds 'notes.odt' and is not an output of msfusion" -- \
    msf_reconstruct "$SEQ" -frames 0:0 -panels 0 -o "$T/foreign"
  check "reconstruct: failed run in an existing OUT" 1 "frame range 0:100000" -- \
    msf_reconstruct "$SEQ" -frames 0:100000 -o "$T/killed/out"
  if ! grep -q previous "$T/killed/out/summary.json" || [ -e "$T/killed/.out.partial.999999999.0" ] ||
     [ ! -e "$T/foreign/notes.odt" ]; then
    failures=$((failures + 1))
    echo "FAIL  reconstruct: the previous OUT changed, a killed run's staging folder remains or a user's file went"
    ls -la "$T/killed" "$T/killed/out" "$T/foreign"
  fi
  # Nothing of the user's is lost: each folder below must be byte for byte as it was.
  D=$T/dataloss
  mkdir -p "$D/seq/velodyne" "$D/seq/image_0" "$D/seq/image_1" "$D/seq/image_2" "$D/poses" "$D/home"
  cp "$SEQ/calib.txt" "$SEQ/times.txt" "$D/seq/"
  for c in velodyne image_0 image_1 image_2; do
    for f in "$SEQ/$c"/000000.*; do cp "$f" "$D/seq/$c/"; done
  done
  head -n 1 "$KITTI/odometry/poses/04.txt" >"$D/poses/04.txt"
  echo "my notes" >"$D/home/notes.txt" && echo "a,b" >"$D/home/data.csv" &&
    printf '%%YAML:1.0\npipeline:\n  queue_capacity: 2\n' >"$D/home/my.yaml" && cp "$D/seq/image_2/000000.png" "$D/home/photo.png"
  mkdir -p "$D/mine/folder.pcd" && cp "$F/dense.pcd" "$D/mine/cloud.pcd" && cp "$F/bomb.ply" "$D/mine/mesh.ply" &&
    cp "$D/home/notes.txt" "$D/home/data.csv" "$D/home/photo.png" "$D/mine/"
  mkdir -p "$D/mine/config" "$D/mine/docs" && cp "$D/home/my.yaml" "$D/mine/config/kitti.yaml"
  before=$(cd "$D" && find . -type f -exec md5sum {} + | sort)
  check "reconstruct -o HOME/. over a user's files" 1 "holds 'data.csv' and is not an output of msfusion" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -o "$D/home/."
  check "reconstruct -o SEQ/image_2" 1 "holds '000000.png' and is not an output of msfusion" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -o "$D/seq/image_2"
  check "reconstruct -o ../poses" 1 "holds '04.txt' and is not an output of msfusion" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -o "$D/poses"
  check "reconstruct -poses inside OUT" 1 "input '.*/home/data.csv' lies inside the output folder" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -poses "$D/home/data.csv" -o "$D/home"
  check "reconstruct -config inside OUT" 1 "input '.*/home/my.yaml' lies inside the output folder" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -config "$D/home/my.yaml" -o "$D/home"
  check "reconstruct -o the dataset itself" 1 "input '.*/seq' lies inside the output folder" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -o "$D/seq"
  ln -s "$D/home" "$D/homelink"
  check "reconstruct -o a symbolic link to a user's folder" 1 "output folder '.*/homelink' is a symbolic link \(to '.*/home'\), which the run's folder would replace: give the folder it points to" -- \
    msf_reconstruct "$D/seq" -frames 0:0 -panels 0 -o "$D/homelink"
  if [ ! -L "$D/homelink" ]; then
    failures=$((failures + 1))
    echo "FAIL  reconstruct -o a symbolic link: the link went"
  fi
  check "synth -o over a user's folder" 1 "holds 'data.csv' and is not an output of msfusion" -- \
    msf_synth -frames 1 -o "$D/home"
  check "batch -o over a user's folder" 1 "holds '(data.csv|notes.txt|my.yaml|photo.png)', which is not a batch's" -- \
    msf_batch -o "$D/home" -local 1 "$SEQ"
  check "batch: a drive whose poses are not known" 1 "drive 'seq' .* has no poses: a batch merges drives whose poses share a world" -- \
    msf_batch -o out -local 1 "$D/seq"
  check "batch -stream below the integrator's reach" 1 "streaming.active_radius_m 30 is below .* the integrator's reach" -- \
    msf_batch -o out -local 1 -stream 30 "$SEQ"
  check "eval_mesh: a sequence without synthetic truth" 1 "is not a synthetic sequence \(no gt/\)" -- \
    msf_eval_mesh "$F/bomb.ply" "$SEQ"
  check "kitti2pcd -output_dir over a user's folder" 1 "holds 'data.csv' and is not an output of msfusion" -- \
    msf_kitti2pcd -input_dir "$D/seq/velodyne" -output_dir "$D/home"
  check "lambda_study -o over a user's folder" 1 "holds 'data.csv' and is not an output of msfusion" -- \
    msf_lambda_study -frames 1 -o "$D/home"
  # A file the user names as a tool's output is theirs: refused unless -overwrite says otherwise.
  check "project over a user's .pcd" 1 "output '.*/mine/cloud.pcd' exists; give -overwrite to replace it" -- \
    msf_project "$SCAN" "$D/mine/cloud.pcd" -calib "$SEQ/calib.txt"
  check "project into a folder named .pcd" 1 "output '.*/mine/folder.pcd' is a folder, not a file" -- \
    msf_project "$SCAN" "$D/mine/folder.pcd" -calib "$SEQ/calib.txt" -overwrite
  check "interpolate over a user's .pcd" 1 "output '.*/mine/cloud.pcd' exists; give -overwrite" -- \
    msf_interpolate "$SCAN" "$D/mine/cloud.pcd" -calib "$SEQ/calib.txt"
  check "kitti2pcd over a user's .pcd" 1 "output '.*/mine/cloud.pcd' exists; give -overwrite" -- \
    msf_kitti2pcd "$SCAN" "$D/mine/cloud.pcd"
  check "stereo -disparity_png over a user's photo" 1 "output '.*/mine/photo.png' exists; give -overwrite" -- \
    msf_stereo "$L" "$R" o.pcd -calib "$SEQ/calib.txt" -disparity_png "$D/mine/photo.png"
  check "fuse over a user's .pcd" 1 "output '.*/mine/cloud.pcd' exists; give -overwrite" -- \
    msf_fuse "$F/dense.pcd" "$F/dense.pcd" "$D/mine/cloud.pcd" -calib "$F/camera.yaml"
  check "pcd2png over a user's photo" 1 "output '.*/mine/photo.png' exists; give -overwrite" -- \
    msf_pcd2png "$F/dense.pcd" "$D/mine/photo.png"
  check "integrate -o over a user's .pcd" 1 "output '.*/mine/cloud.pcd' exists; give -overwrite" -- \
    msf_integrate "$F/dense.pcd" -poses "$F/pose.txt" -o "$D/mine/cloud.pcd"
  check "mesh over a user's .ply" 1 "output '.*/mine/mesh.ply' exists; give -overwrite" -- \
    msf_mesh "$F/dense.pcd" "$D/mine/mesh.ply"
  check "odometry -o over a user's notes" 1 "output '.*/mine/notes.txt' exists; give -overwrite" -- \
    msf_odometry "$SEQ" -frames 0:1 -o "$D/mine/notes.txt"
  check "holdout -csv over a user's .csv" 1 "output '.*/mine/data.csv' exists; give -overwrite" -- \
    msf_holdout "$SEQ" -frames 0:0 -csv "$D/mine/data.csv"
  check "eval_odometry -plot over a user's photo" 1 "output '.*/mine/photo.png' exists; give -overwrite" -- \
    msf_eval_odometry "$D/poses/04.txt" "$D/poses/04.txt" -plot "$D/mine/photo.png"
  check "config -write over a user's config/kitti.yaml" 1 \
    "'.*/mine/config/kitti.yaml' is not a file msf_config -write made.*nothing was written" -- \
    msf_config -write "$D/mine"
  check "eval_mesh -o over a user's notes" 1 "output '.*/mine/notes.txt' exists; give -overwrite" -- \
    msf_eval_mesh "$F/bomb.ply" "$SEQ" -o "$D/mine/notes.txt"
  after=$(cd "$D" && find . -type f -exec md5sum {} + | sort)
  cp "$F/dense.pcd" "$T/replaced.pcd"
  check "project -overwrite replaces a file" 0 "Projecting" -- \
    msf_project "$SCAN" "$T/replaced.pcd" -calib "$SEQ/calib.txt" -overwrite
  if cmp -s "$F/dense.pcd" "$T/replaced.pcd"; then
    failures=$((failures + 1))
    echo "FAIL  project -overwrite left the file as it was"
  fi
  if [ "$before" != "$after" ] || [ -n "$(ls -A "$D" | grep -v -x -e seq -e poses -e home -e homelink -e mine)" ]; then
    failures=$((failures + 1))
    echo "FAIL  data loss: a user's folder changed"
    diff <(echo "$before") <(echo "$after") | head
  fi
else
  # Each case of the block above skipped by its name, read from this file, so that the count
  # of cases is the same with the sample and without it.
  mapfile -t kitti_cases < <(sed -n '/^# ---- cases on the KITTI sample/,/^else$/p' "$0" |
                             sed -n 's/^ *check "\([^"]*\)".*/\1/p')
  for c in "${kitti_cases[@]}"; do
    skip "$c"
  done
fi

echo "$cases cases, $failures failed, $skipped skipped; slowest $slowest ms, largest $((largest / 1024)) MB$memory_note"
[ $failures = 0 ]
