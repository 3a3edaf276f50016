#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# msf_reconstruct end to end on KITTI odometry 04 frames 0-9 (the target: >= 10 fps
# on 2 cores, peak memory <= 2 GB): RUNS runs, then the median frames per second (over the
# whole run, and after the first frame), the median per-stage times, the median CPU time of
# the process and the largest peak memory over the runs.
# POSES: msf_reconstruct -poses, dataset (the default) or estimate (the tracking module too), or
# both as dataset,estimate. BIN_DIR may also be several builds, comma-separated (this one and
# main's, say). Every build and every POSES take turns run by run, so that a noisy machine's
# changes of load fall on all alike; each gets its own figures, and the medians are compared
# as ratios to the first build's first POSES.
# Usage: bench/bench_pipeline.sh BIN_DIR[,BIN_DIR...] KITTI_DIR [RUNS] [CONFIG] [POSES]
set -euo pipefail
bins=${1:-build/bin} kitti=${2:-../shared/data/kitti} runs=${3:-5}
config=${4:-$(dirname "$0")/../config/kitti.yaml}
poses=${5:-dataset}
sequence="$kitti/odometry/sequences/04"
[ -d "$sequence" ] || { echo "bench_pipeline: no KITTI sequence at $sequence" >&2; exit 1; }
IFS=, read -r -a bin_list <<< "$bins"
for b in "${bin_list[@]}"; do
  [ -x "$b/msf_reconstruct" ] || { echo "bench_pipeline: no msf_reconstruct in $b" >&2; exit 1; }
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for i in $(seq 1 "$runs"); do
  for k in "${!bin_list[@]}"; do
    for p in ${poses//,/ }; do
      /usr/bin/time -f "%U %S" -o "$out/cpu$k$p$i" \
        "${bin_list[$k]}/msf_reconstruct" "$sequence" -frames 0:9 -panels 0 -config "$config" -poses "$p" -o "$out/$k$p$i" > /dev/null
      # Only the summary is read: the mesh and the volume (~45 MB a run) would fill a small disk.
      find "$out/$k$p$i" -type f ! -name summary.json -delete
    done
  done
done
python3 - "$out" "$runs" "$poses" "${bin_list[@]}" <<'PY'
import json, statistics, sys
out, runs, poses, bins = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(","), sys.argv[4:]
first = None
for k, b in enumerate(bins):
    for p in poses:
        s = [json.load(open(f"{out}/{k}{p}{i}/summary.json")) for i in range(1, runs + 1)]
        cpu = [sum(map(float, open(f"{out}/cpu{k}{p}{i}").read().split()[-2:])) for i in range(1, runs + 1)]
        fps = [x["frames_per_second"] for x in s]
        after = [x["frames_per_second_after_first"] for x in s]
        median = statistics.median(fps)
        first = first or median
        label = f"{b}: " if len(bins) > 1 else ""
        print(f"{label}msf_reconstruct -poses {p}, KITTI 04 frames 0-9, {runs} runs: median {median:.2f} fps "
              f"(min {min(fps):.2f}, max {max(fps):.2f}), peak memory {max(x['peak_memory_mb'] for x in s):.0f} MiB"
              + (f"; {median / first:.3f} x the first" if median != first or k or p != poses[0] else ""))
        print(f"  after the first frame (the pipeline full): median {statistics.median(after):.2f} fps "
              f"(min {min(after):.2f}, max {max(after):.2f}); first frame done at "
              f"{statistics.median(x['first_frame_s'] for x in s):.3f} s (median)")
        print(f"  process CPU time (user + system, the whole run with start-up and output) median {statistics.median(cpu):.2f} s")
        for stage in s[0]["stage_ms"]:
            print(f"  {stage:10s} median of per-run medians {statistics.median(x['stage_ms'][stage]['median'] for x in s):7.1f} ms")
        if "estimate_ms" in s[0]["trajectory"]:
            print(f"  odometry   median of per-run medians "
                  f"{statistics.median(x['trajectory']['estimate_ms']['median'] for x in s):7.1f} ms (its own thread)")
PY
