#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# What docs/scale.md sizes the batch from (figures in docs/results.md, "Many drives, one map"):
#  1. a real KITTI drive streamed (04_10_50, 0.1 m voxels): frames per second, peak memory, the
#     store's bytes and tiles per frame and per metre;
#  2. three overlapping synthetic drives of one street (msf_synth -street_m, 60 frames each,
#     0.1 m voxels, moving cars on): the batch on this machine (-local 1) against the drives' own
#     run time (the machinery's overhead), the merge's and the mesh's time per tile, and the maps
#     scored against the street's truth beside the one-process map;
#  3. the merge's time against its fan-in: one drive's store merged with k copies of itself;
#  4. the same batch on Slurm (SLURM_CONF), each task alone on the node (-cpus: all its CPUs;
#     -merge_tasks 1), so that the machinery's overhead is the wall less the tasks' own time.
# usage: bench/bench_batch.sh BIN_DIR KITTI_DIR [WORK_DIR]   (WORK_DIR is kept; ~15 min on 2 cores)
set -euo pipefail
bin=$(cd "$1" && pwd)
kitti=$2
work=${3:-/tmp/msf_bench_batch}
mkdir -p "$work"
cd "$work"
json() { grep -o "\"$2\": [0-9.e+-]*" "$1" | head -1 | awk '{print $2}'; }
# The batch machinery's own time: submit-to-map wall less the drives' msf_reconstruct runs and
# the merge, mesh and finish tasks' time, against the drives' time. Exact when the tasks run one
# after another (-local 1; -slurm with -merge_tasks 1 and drives of -cpus all the CPUs).
overhead() { # summary.json, wall seconds
  awk -v wall="$2" '/"reconstruct_s":/ {match($0, /"reconstruct_s": [0-9.e+-]+/); split(substr($0, RSTART, RLENGTH), a, ": "); drives += a[2]}
    /"(merge|mesh|finish)_s":/ {gsub(/[",]/, ""); tasks += $2}
    END {printf "drives %.1f s, merge+mesh+finish %.1f s, machinery %.1f s = %.2f %% of the drives\n", drives, tasks, wall - drives - tasks, 100 * (wall - drives - tasks) / drives}' "$1"
}

echo "== 1. KITTI odometry 04_10_50 streamed at 0.1 m voxels"
rm -rf kitti_drive
/usr/bin/time -f "%e s wall, %U s user, %S s system, %M KiB peak" "$bin/msf_reconstruct" "$kitti/odometry/sequences/04_10_50" \
  -o kitti_drive -stream 101 -panels 0 > kitti_drive.log 2> kitti_drive.time
frames=$(json kitti_drive/summary.json frames_done || true)
echo "frames per second $(json kitti_drive/summary.json frames_per_second), $(cat kitti_drive.time)"
echo "store: tsdf/ $(du -sb kitti_drive/tsdf | cut -f1) bytes, tiles/ $(du -sb kitti_drive/tiles | cut -f1) bytes," \
     "$(($(ls kitti_drive/tsdf | wc -l) - 1)) tiles"
awk 'NR == 1 {x0 = $4; z0 = $12} {x = $4; z = $12} END {printf "path %.1f m (first to last pose)\n", sqrt((x - x0)^2 + (z - z0)^2)}' \
  kitti_drive/poses.txt

echo "== 2. Three drives of one street"
synth() { [ -e "$1/gt/scene.ply" ] || "$bin/msf_synth" -o "$@" -frames 60 -seed 3 -street_m 130 > /dev/null; }
synth a
synth b -start_m 30
synth c -start_m 125 -reverse
rm -rf batch one
/usr/bin/time -f "%e s wall, %U s user, %S s system (the batch and its children)" -o batch.time \
  "$bin/msf_batch" -o batch -local 1 -merge_tasks 2 -stream 101 a b c > batch.log 2>&1
echo "batch -local 1: $(cat batch.time)"
overhead batch/map/summary.json "$(awk '{print $1}' batch.time)"
grep -o '"reconstruct_s": [0-9.]*' batch/map/summary.json
for key in tiles tiles_shared blocks voxels_shared voxels_capped merge_s mesh_s finish_s triangles; do
  echo "$key $(json batch/map/summary.json $key)"
done
"$bin/msf_batch" -o one -one_process -stream 101 a b c > one.log 2>&1
echo "one process: $(json one/summary.json wall_s) s"
for mesh in batch/drives/a/mesh.ply batch/drives/b/mesh.ply batch/drives/c/mesh.ply batch/map/mesh.ply one/mesh.ply; do
  echo "$mesh: $("$bin/msf_eval_mesh" "$mesh" a b c | tail -1)"
done

echo "== 3. The merge against its fan-in (one drive's store, k copies)"
for k in 1 2 4 8; do
  rm -rf fanin_$k merged_$k
  mkdir -p fanin_$k
  stores=()
  for i in $(seq "$k"); do
    cp -al batch/drives/a "fanin_$k/s$i"
    stores+=("fanin_$k/s$i")
  done
  "$bin/msf_merge" -o "merged_$k" "${stores[@]}" > "merged_$k.log" 2>&1
  echo "fan-in $k: merge $(json merged_$k/summary.json merge_s) s, mesh $(json merged_$k/summary.json mesh_s) s," \
       "$(json merged_$k/summary.json tiles) tiles, $(json merged_$k/summary.json blocks) blocks"
done

echo "== 4. The same batch on Slurm (when SLURM_CONF names a cluster that takes jobs)"
if sinfo -h >/dev/null 2>&1; then
  rm -rf slurm
  start=$(date +%s.%N)
  "$bin/msf_batch" -o slurm -slurm -wait -cpus "$(nproc)" -merge_tasks 1 -stream 101 a b c > slurm.log 2>&1
  end=$(date +%s.%N)
  echo "batch -slurm (submit to map): $(echo "$end - $start" | bc) s wall"
  overhead slurm/map/summary.json "$(echo "$end - $start" | bc)"
  grep -o '"reconstruct_s": [0-9.]*' slurm/map/summary.json
  for key in merge_s mesh_s finish_s; do echo "$key $(json slurm/map/summary.json $key)"; done
else
  echo "no Slurm cluster: skipped (scripts/slurm_local.sh start; export SLURM_CONF=...)"
fi
