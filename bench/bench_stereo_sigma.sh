#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Is the fusion's stereo sigma right? SGBM's disparity error by its confidence, against the
# sigma the fusion assumes for that confidence (fusion.stereo_sigma_min_px / max_px), on the
# three datasets the pipeline is tuned on:
#   - KITTI odometry 04 frames 0, 3, 6, 9 and raw drive 0009 frames 0, 2, 4: msf_stereo without
#     a LiDAR prior (config/kitti.yaml), the truth the frame's whole scan projected into camera 0
#     (msf_project, msf_pcd2png -disparity: a return the LiDAR sees past a foreground edge
#     counts against stereo there, which the robust sigma ignores and the outlier share does not);
#   - the synthetic street (msf_synth, 40 frames) frames 5, 20 and 35 against their exact
#     disparity (config/synthetic.yaml).
# Prints msf_eval_disparity -confidence's table for each (docs/results.md, "The stereo sigma against SGBM's measured error").
#
# Usage: bench/bench_stereo_sigma.sh BIN_DIR KITTI_DIR [OUT]
#   OUT keeps the disparities, clouds and truths (and the street, which later runs reuse).
set -euo pipefail
bin=${1:?usage: bench_stereo_sigma.sh BIN_DIR KITTI_DIR [OUT]}
kitti=${2:?usage: bench_stereo_sigma.sh BIN_DIR KITTI_DIR [OUT]}
out=${3:-}
here=$(cd "$(dirname "$0")/.." && pwd)
source "$here/bench/bench_args.sh"
need_tools bench_stereo_sigma "$bin" msf_stereo msf_project msf_pcd2png msf_eval_disparity msf_synth
odometry="$kitti/odometry/sequences/04"
raw_date="$kitti/raw/2011_09_26"
raw="$raw_date/2011_09_26_drive_0009_sync"
need_sequences bench_stereo_sigma "$odometry" "$raw"
output_folder

quiet() { # log command...: runs it, shows its log when it fails
  local log=$1
  shift
  "$@" > "$log" 2>&1 || { echo "bench_stereo_sigma: failed: $* (log: $log)" >&2; tail -5 "$log" >&2; exit 1; }
}

# stereo NAME CALIB CONFIG LEFT RIGHT FRAME: the estimate's disparity PNG and confidence cloud
stereo() {
  mkdir -p "$out/$1/est" "$out/$1/confidence"
  quiet "$out/$1/stereo.log" "$bin/msf_stereo" "$4" "$5" "$out/$1/confidence/$6.pcd" -calib "$2" -config "$3" \
    -disparity_png "$out/$1/est/$6.png"
}
# lidar_truth NAME CALIB SCAN FRAME [msf_project options]: the scan's disparity in camera 0
lidar_truth() {
  local name=$1 calib=$2 scan=$3 frame=$4
  shift 4
  mkdir -p "$out/$name/gt"
  quiet "$out/$name/project.log" "$bin/msf_project" "$scan" "$out/$name/scan.pcd" -calib "$calib" -overwrite "$@"
  quiet "$out/$name/png.log" "$bin/msf_pcd2png" "$out/$name/scan.pcd" "$out/$name/gt/$frame.png" -disparity \
    -calib "$calib"
}
report() { # NAME CONFIG TITLE
  echo "== $3"
  "$bin/msf_eval_disparity" "$out/$1/gt" "$out/$1/est" -confidence "$out/$1/confidence" -config "$2" |
    sed -n '/error by stereo confidence/,$p'
  echo
}

kitti_config="$here/config/kitti.yaml"
synthetic_config="$here/config/synthetic.yaml"
for i in 000000 000003 000006 000009; do
  stereo odometry04 "$odometry/calib.txt" "$kitti_config" "$odometry/image_0/$i.png" "$odometry/image_1/$i.png" "$i"
  lidar_truth odometry04 "$odometry/calib.txt" "$odometry/velodyne/$i.bin" "$i"
done
for i in 0 2 4; do
  frame=$(printf '%06d' "$i") file=$(printf '%010d' "$i")
  stereo raw0009 "$raw_date" "$kitti_config" "$raw/image_00/data/$file.png" "$raw/image_01/data/$file.png" "$frame"
  lidar_truth raw0009 "$raw_date" "$raw/velodyne_points/data/$file.bin" "$frame" -image_size 1242x375
done
street="$out/street40"
if [ ! -f "$street/gt/scene.ply" ] || [ "$(ls "$street/gt/disp_0" | wc -l)" -ne 40 ]; then
  quiet "$out/street40.log" "$bin/msf_synth" -o "$street" -frames 40
fi
mkdir -p "$out/street/gt"
for i in 000005 000020 000035; do
  stereo street "$street/sequences/00/calib.txt" "$synthetic_config" "$street/sequences/00/image_0/$i.png" \
    "$street/sequences/00/image_1/$i.png" "$i"
  cp "$street/gt/disp_0/$i.png" "$out/street/gt/$i.png"
done

report odometry04 "$kitti_config" "KITTI odometry 04, frames 0 3 6 9 (truth: the LiDAR)"
report raw0009 "$kitti_config" "KITTI raw 0009, frames 0 2 4 (truth: the LiDAR)"
report street "$synthetic_config" "synthetic street, frames 5 20 35 (truth: exact)"
