#!/usr/bin/env bash
# make demo: the main job on the built-in default data.
# Usage: scripts/demo.sh BIN_DIR OUT_DIR KITTI_DIR
set -euo pipefail
bin=${1:-build/bin} out=${2:-out/demo} kitti=${3:-../shared/data/kitti}
mkdir -p "$out"

# Until the pipeline (msf_reconstruct) lands, the demo chains the tools that exist on the
# KITTI sample frame: scan -> .pcd -> description.
seq="$kitti/odometry/sequences/04"
if [ ! -d "$seq" ]; then
  echo "demo: the KITTI sample is not at $kitti (pass KITTI_DIR=...)" >&2
  exit 1
fi
"$bin/msf_kitti2pcd" "$seq/velodyne/000000.bin" "$out/scan.pcd"
"$bin/msf_info" "$out/scan.pcd"
echo "demo: outputs in $out"
