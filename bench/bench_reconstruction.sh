#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Evaluation protocol 4 on the three datasets the integrator is tuned on: msf_reconstruct
# -holdout -compare_sources on KITTI odometry 04 frames 0-9 and raw drive 0009 frames 0-4, and
# msf_reconstruct -compare_sources on a 40-frame synthetic street (exact depth, true surface).
# Prints one table per dataset: per depth source (the fused mesh, the per-frame fused depth,
# the mesh of the interpolated LiDAR alone, of SGBM alone) coverage and D1 (missing = bad)
# within the map's depth range and over all ground-truth pixels, on KITTI also within range on
# the lasting pixels (those no nearby frame's scan saw through); on the street also the
# meshes' accuracy, completeness and ghost share, and completeness by the nearest distance
# each piece of the surface was seen from.
#
# Usage: bench/bench_reconstruction.sh BIN_DIR KITTI_DIR [OUT [msf_reconstruct options...]]
#   OUT keeps each run's folder (summary.json, report.md, meshes) and the generated street,
#   which later runs into the same OUT reuse; without it all goes to a temporary folder.
#   Options after OUT go to every run, e.g. -config config/kitti.yaml or -lambda 5.
set -euo pipefail
bin=${1:?usage: bench_reconstruction.sh BIN_DIR KITTI_DIR [OUT [options...]]}
kitti=${2:?usage: bench_reconstruction.sh BIN_DIR KITTI_DIR [OUT [options...]]}
out=${3:-}
shift $(($# < 3 ? $# : 3))
options=("$@")
source "$(dirname "$0")/bench_args.sh"
need_tools bench_reconstruction "$bin" msf_reconstruct msf_synth
odometry="$kitti/odometry/sequences/04"
raw="$kitti/raw/2011_09_26/2011_09_26_drive_0009_sync"
need_sequences bench_reconstruction "$odometry" "$raw"
output_folder

run() { # name dataset options...
  local name=$1 dataset=$2
  shift 2
  local start=$SECONDS
  rm -rf "${out:?}/$name"
  if ! "$bin/msf_reconstruct" "$dataset" -panels 0 -o "$out/$name" "$@" "${options[@]}" > "$out/$name.log" 2>&1; then
    echo "bench_reconstruction: msf_reconstruct failed on $dataset (log: $out/$name.log)" >&2
    tail -5 "$out/$name.log" >&2
    exit 1
  fi
  echo "$name: $((SECONDS - start)) s" >> "$out/times.txt"
}

: > "$out/times.txt"
run odometry04 "$odometry" -frames 0:9 -holdout -compare_sources
run raw0009 "$raw" -frames 0:4 -holdout -compare_sources
street="$out/street40"
if [ ! -f "$street/gt/scene.ply" ] || [ "$(ls "$street/gt/depth_0" | wc -l)" -ne 40 ]; then
  "$bin/msf_synth" -o "$street" -frames 40 > "$out/street40.log" 2>&1 ||
    { echo "bench_reconstruction: msf_synth failed (log: $out/street40.log)" >&2; exit 1; }
fi
run synthetic "$street" -compare_sources

python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
times = dict(line.strip().split(": ") for line in open(f"{out}/times.txt"))
titles = {"odometry04": "KITTI odometry 04, frames 0-9", "raw0009": "KITTI raw 2011_09_26_drive_0009, frames 0-4",
          "synthetic": "synthetic street, 40 frames"}
def pct(x): return "      - " if x is None else f"{100 * x:6.2f}%"
def num(x, f="6.3f"): return format("-", ">" + f.split(".")[0]) if x is None else format(x, f)
for name, title in titles.items():
    s = json.load(open(f"{out}/{name}/summary.json"))
    e = s["reconstruction_evaluation"]
    print(f"\n{title} ({times[name]}): {e['truth']}, {e['gt_pixels']} pixels; within range: true depth <= {e['range_m']:g} m")
    head = f"  {'':12s} {'within range':>16s}   {'all pixels':>16s}"
    cols = f"  {'source':12s} {'coverage':>8s} {'D1':>7s}   {'coverage':>8s} {'D1':>7s}"
    synthetic = any("accuracy" in r for r in e["rows"].values())
    if e.get("transient_split"):
        head += f"   {'lasting, in range':>16s}"
        cols += f"   {'coverage':>8s} {'D1':>7s}"
    if synthetic:
        head += f"   {'mesh vs true surface':>27s}"
        cols += f"   {'accuracy':>8s} {'complete':>8s} {'ghosts':>7s}"
    print(head)
    print(cols)
    for source, r in e["rows"].items():
        line = (f"  {source:12s} {num(r['within_range']['coverage'], '8.3f')} {pct(r['within_range']['d1_all'])}"
                f"   {num(r['all']['coverage'], '8.3f')} {pct(r['all']['d1_all'])}")
        if e.get("transient_split"):
            lasting = r["lasting_within_range"]
            line += f"   {num(lasting['coverage'], '8.4f')} {pct(lasting['d1_all'])}"
        if synthetic:
            a, g = r.get("accuracy"), r.get("ghosts")
            line += (f"   {num(a and a['accuracy_mean_m'], '7.3f')}{' m' if a else '  '} {pct(a and a['completeness'])}"
                     f" {pct(g and g['share'])}")
        print(line)
    if e.get("moving_split"):
        print("  (static pixels; moving objects apart in summary.json)")
    if e.get("transient_split"):
        print("  (lasting: the held-out returns no scan of a frame around saw through; the transient ones in"
              " summary.json)")
    if synthetic:
        for source, r in e["rows"].items():
            bands = (r.get("accuracy") or {}).get("completeness_by_nearest_view", [])
            if bands:
                print(f"  {source} completeness by the nearest distance seen from: " + ", ".join(
                    f"{b['lower_m']:g}-{b['upper_m']:g} m {100 * b['completeness']:.1f}% ({b['samples']})" for b in bands))
    if synthetic and e.get("no_ghosts"):
        print(f"  ghosts: {e['no_ghosts']}")
print(f"\nRuns, logs and reports: {out}")
PY
