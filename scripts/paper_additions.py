#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""What each of the project's additions to the paper adds (docs/paper.md).

config/paper.yaml lists, key by key, what the paper does where the project's defaults
(config/kitti.yaml) do more. An addition is a set of those keys. For each addition and
dataset this runs the paper with the addition (paper.yaml without its keys) and ours without
it (a file of only its keys), beside the paper and ours, and prints one markdown row each:
  depth additions: protocol 2, msf_holdout -methods fused (D1 with missing = bad, depth MAE);
  map additions:   protocol 4, msf_reconstruct (-holdout on KITTI): the mesh's coverage and D1
                   within range; on the synthetic street its accuracy and completeness.

Usage: scripts/paper_additions.py BIN_DIR KITTI_DIR STREET_DIR [--map] [--only NAME,...]
  STREET_DIR: a synthetic sequence (build/bin/msf_synth -o /tmp/syn10 -frames 10).
  Datasets: odometry 04 frames 0-9, raw 0009 frames 0-4, the street's frames 0-9.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# name, keys of config/paper.yaml that switch it off, what it changes ("depth" or "map")
ADDITIONS = [
    ("canvas margin (16 px around the image)", ["projection.margin_px"], "depth"),
    ("inverse depth", ["interpolation.inverse_depth"], "depth"),
    ("edge tests", ["interpolation.edge_test"], "depth"),
    ("column slices seeded by short row bridges", ["interpolation.column_seed_gap_px"], "depth"),
    ("shorter-gap combination of row and column", ["interpolation.combine"], "depth"),
    ("Gaussian pass over the holes only", ["interpolation.gaussian_smooth_valid"], "depth"),
    ("native SGBM engine", ["stereo.engine"], "depth"),
    # guidance exists in the native engine only (OpenCV ignores it)
    ("guidance (native engine)", ["stereo.guidance", "stereo.engine"], "depth"),
    ("narrowed range", ["stereo.prior_search_range", "pipeline.stereo_prior"], "depth"),
    ("uncertainty fusion", ["fusion.method"], "depth"),
    ("eq. 6 weights relative to stereo's", ["fusion.paper_weights"], "depth"),
    ("edge support", ["fusion.edge_support"], "depth"),
    ("facade extension", ["fusion.facade_extension"], "depth"),
    ("the integrator's settings (all below)", ["tsdf_integrator.*", "marching_cubes.min_weight", "marching_cubes.max_unseen_corners"], "map"),
    ("per-pixel weights", ["tsdf_integrator.weighting"], "map"),
    ("plane distance", ["tsdf_integrator.signed_distance"], "map"),
    ("bands of 2 sigma", ["tsdf_integrator.truncation_sigmas"], "map"),
    ("min_pixel_weight", ["tsdf_integrator.min_pixel_weight"], "map"),
    ("space carving", ["tsdf_integrator.space_carving"], "map"),
    ("weight drop-off", ["tsdf_integrator.weight_dropoff"], "map"),
    ("bilinear depth", ["tsdf_integrator.interpolate_depth"], "map"),
    ("lambda 0 (eq. 7 off)", ["tsdf_integrator.lambda", "tsdf_integrator.solve"], "map"),
    ("marching cubes min_weight", ["marching_cubes.min_weight"], "map"),
    ("a cube's corner no frame reached", ["marching_cubes.max_unseen_corners"], "map"),
]


def paper_keys():
    """config/paper.yaml as [(section, key, value line)], comments dropped."""
    entries, section = [], None
    for line in open(os.path.join(ROOT, "config", "paper.yaml")):
        if not line.strip() or line.lstrip().startswith("#") or line.startswith("%"):
            continue
        if not line.startswith(" "):
            section = line.split(":")[0]
        else:
            entries.append((section, line.split(":")[0].strip(), line.rstrip("\n")))
    return entries


def matches(section, key, patterns):
    return any(p in (section + "." + key, section + ".*") for p in patterns)


def write_config(path, entries):
    """`entries` as a config file at `path`; None for no entries: the tools' defaults (an empty file is refused)."""
    if not entries:
        return None
    by_section = {}
    for section, _, line in entries:
        by_section.setdefault(section, []).append(line)
    with open(path, "w") as f:
        f.write("%YAML:1.0\n")
        for section, lines in by_section.items():
            f.write(section + ":\n" + "\n".join(lines) + "\n")
    return path


def config_option(config):
    return ["-config", config] if config else []


def run(cmd):
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit("paper_additions: %s failed:\n%s" % (" ".join(cmd), result.stderr))
    return result.stdout


def depth_figures(bin_dir, dataset, frames, config, work):
    """Protocol 2 of `config`'s steps 1-4: (D1 % with missing = bad, MAE m); the street's all pixels."""
    table = os.path.join(work, "rows.csv")
    run([os.path.join(bin_dir, "msf_holdout"), dataset, "-frames", frames, "-methods", "fused", "-csv", table,
         "-overwrite"] + config_option(config))
    for row in csv.DictReader(open(table)):
        if row.get("region", "all") == "all":
            return 100 * float(row["d1_all"]), float(row["mae_m"])
    sys.exit("paper_additions: no row in " + table)


def map_figures(bin_dir, dataset, frames, config, work, synthetic):
    """Protocol 4 of `config`: the mesh's (coverage, D1 %) within range, or on the street (accuracy m, completeness %)."""
    out = os.path.join(work, "map")
    cmd = [os.path.join(bin_dir, "msf_reconstruct"), dataset, "-o", out, "-frames", frames, "-panels", "0"]
    cmd += config_option(config)
    run(cmd + ([] if synthetic else ["-holdout"]))
    summary = json.load(open(os.path.join(out, "summary.json")))
    if synthetic:
        m = summary["mesh_accuracy"]
        return m["accuracy_mean_m"], 100 * m["completeness"]
    m = summary["reconstruction_evaluation"]["rows"]["mesh"]["within_range"]
    return m["coverage"], 100 * m["d1_all"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("bin_dir")
    parser.add_argument("kitti_dir")
    parser.add_argument("street_dir")
    parser.add_argument("--map", action="store_true", help="also the map additions (protocol 4, slower)")
    parser.add_argument("--only", default="", help="comma-separated addition names (a prefix is enough)")
    args = parser.parse_args()
    datasets = [("odometry 04", os.path.join(args.kitti_dir, "odometry/sequences/04"), "0:9", False),
                ("raw 0009", os.path.join(args.kitti_dir, "raw/2011_09_26/2011_09_26_drive_0009_sync"), "0:4", False),
                ("street", args.street_dir, "0:9", True)]
    only = [o for o in args.only.split(",") if o]
    entries = paper_keys()
    with tempfile.TemporaryDirectory() as work:
        paper = write_config(os.path.join(work, "paper.yaml"), entries)
        ours = write_config(os.path.join(work, "ours.yaml"), [])
        for stage in ("depth", "map"):
            if stage == "map" and not args.map:
                continue
            measure = depth_figures if stage == "depth" else map_figures
            unit = ("D1 %", "MAE m") if stage == "depth" else ("coverage / accuracy m", "D1 % / completeness %")
            print("\n%s additions: paper + addition / ours - addition (%s, %s)\n" % (stage, unit[0], unit[1]))

            def figures(name, dataset, frames, config, synthetic):
                args_ = (args.bin_dir, dataset, frames, config, work)
                a, b = measure(*args_) if stage == "depth" else measure(*args_, synthetic)
                return "%.3f / %.2f" % (a, b) if stage == "map" else "%.2f %% / %.3f m" % (a, b)

            print("| addition | " + " | ".join(d[0] for d in datasets) + " |")
            print("|---|" + "---|" * len(datasets))
            print("| paper / ours | " + " | ".join(
                figures("paper", d[1], d[2], paper, d[3]) + " ; " + figures("ours", d[1], d[2], ours, d[3])
                for d in datasets) + " |", flush=True)
            for name, patterns, kind in ADDITIONS:
                if kind != stage or (only and not any(name.startswith(o) for o in only)):
                    continue
                plus = write_config(os.path.join(work, "plus.yaml"),
                                    [e for e in entries if not matches(e[0], e[1], patterns)])
                minus = write_config(os.path.join(work, "minus.yaml"),
                                     [e for e in entries if matches(e[0], e[1], patterns)])
                cells = [figures(name, d[1], d[2], plus, d[3]) + " ; " + figures(name, d[1], d[2], minus, d[3])
                         for d in datasets]
                print("| %s | %s |" % (name, " | ".join(cells)), flush=True)


if __name__ == "__main__":
    main()
