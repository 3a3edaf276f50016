#!/usr/bin/env bash
# msf_reconstruct end to end on KITTI odometry 04 frames 0-9 (issue #7's target: >= 10 fps
# on 2 cores, peak memory <= 2 GB): RUNS runs, then the median frames per second (over the
# whole run, and after the first frame), the median per-stage times and the largest peak
# memory over the runs.
# POSES: msf_reconstruct -poses, dataset (the default) or estimate (the tracking module too), or
# both as dataset,estimate: then the two take turns run by run, so that a noisy machine's
# changes of load fall on both alike, and each gets its own figures.
# Usage: bench/bench_pipeline.sh BIN_DIR KITTI_DIR [RUNS] [CONFIG] [POSES]
set -euo pipefail
bin=${1:-build/bin} kitti=${2:-../shared/data/kitti} runs=${3:-5}
config=${4:-$(dirname "$0")/../config/kitti.yaml}
poses=${5:-dataset}
sequence="$kitti/odometry/sequences/04"
[ -d "$sequence" ] || { echo "bench_pipeline: no KITTI sequence at $sequence" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for i in $(seq 1 "$runs"); do
  for p in ${poses//,/ }; do
    "$bin/msf_reconstruct" "$sequence" -frames 0:9 -panels 0 -config "$config" -poses "$p" -o "$out/$p$i" > /dev/null
  done
done
python3 - "$out" "$runs" "$poses" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
for poses in sys.argv[3].split(","):
    s = [json.load(open(f"{out}/{poses}{i}/summary.json")) for i in range(1, runs + 1)]
    fps = [x["frames_per_second"] for x in s]
    after = [x["frames_per_second_after_first"] for x in s]
    print(f"msf_reconstruct -poses {poses}, KITTI 04 frames 0-9, {runs} runs: median {statistics.median(fps):.2f} fps "
          f"(min {min(fps):.2f}, max {max(fps):.2f}), peak memory {max(x['peak_memory_mb'] for x in s):.0f} MiB")
    print(f"  after the first frame (the pipeline full): median {statistics.median(after):.2f} fps "
          f"(min {min(after):.2f}, max {max(after):.2f}); first frame done at "
          f"{statistics.median(x['first_frame_s'] for x in s):.3f} s (median)")
    for stage in s[0]["stage_ms"]:
        print(f"  {stage:10s} median of per-run medians {statistics.median(x['stage_ms'][stage]['median'] for x in s):7.1f} ms")
    if "estimate_ms" in s[0]["trajectory"]:
        print(f"  odometry   median of per-run medians "
              f"{statistics.median(x['trajectory']['estimate_ms']['median'] for x in s):7.1f} ms (its own thread)")
PY
