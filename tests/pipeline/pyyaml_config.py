#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""PyYAML (Debian's python3-yaml) and msfusion read each other's configuration files.

usage: pyyaml_config.py MSF_CONFIG SOURCE_DIR WORK_DIR

PyYAML reads what the project writes (msf_config prints what msf_reconstruct saves as
OUT/config.yaml) with every number and boolean typed as one; a file PyYAML dumps from that
(block and flow style) is read by the project to the very same configuration; and a file
written by PyYAML from a dict of values other than the defaults gives the project those values.
"""
import math
import os
import re
import subprocess
import sys

import yaml


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def msf_config(tool, *args):
    result = subprocess.run([tool, *args], capture_output=True, text=True)
    if result.returncode != 0:
        fail("msf_config " + " ".join(args) + " exited " + str(result.returncode) + ":\n" + result.stderr)
    return result.stdout


def expected_value(text):
    """The value a YAML reader must see in one of our values, from its text alone."""
    if text in ("true", "false"):
        return text == "true"
    if text.startswith("["):
        return [expected_value(item.strip()) for item in text[1:-1].split(",") if item.strip()]
    if re.fullmatch(r"-?[0-9]+", text):
        return int(text)
    if re.fullmatch(r"-?[0-9]+\.[0-9]*(e[-+][0-9]+)?|-?\.inf|\.nan", text):
        return float(text.replace(".inf", "inf").replace(".nan", "nan"))
    return text


def check_pyyaml_reads(text, what):
    """PyYAML reads `text` (sections of `  key: value` lines) with each value typed as written."""
    data = yaml.safe_load(text)
    section = None
    keys = 0
    for line in text.splitlines():
        if not line or line.lstrip().startswith("#"):
            continue
        if not line.startswith(" "):
            section = line.rstrip(":")
            if not isinstance(data.get(section), dict):
                fail(what + ": PyYAML does not read section " + section + " as a map")
            continue
        key, value = line.strip().split(": ", 1)
        got, want = data[section][key], expected_value(value)
        same_type = type(got) is type(want) or (isinstance(want, list) and isinstance(got, list))
        same = got == want or (isinstance(want, float) and math.isnan(want) and math.isnan(got))
        if not same_type or not same:
            fail("%s: PyYAML reads %s.%s: %s as %r (%s), not %r" % (what, section, key, value, got,
                                                                    type(got).__name__, want))
        keys += 1
    if keys < 100:
        fail(what + ": only %d keys" % keys)
    return data


def check_round_trip(tool, work, printed, data, what):
    """A file PyYAML dumps from `data` reads to the configuration that printed as `printed`."""
    for flow in (False, True):
        path = os.path.join(work, "pyyaml_%s_%s.yaml" % (what, "flow" if flow else "block"))
        with open(path, "w") as f:
            yaml.safe_dump(data, f, default_flow_style=flow)
        again = msf_config(tool, "-config", path)
        if again != printed:
            fail("%s: PyYAML's dump (%s style) reads to another configuration:\n%s" % (what, "flow" if flow else
                                                                                     "block", again))


def main():
    tool, source, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    configurations = {
        "defaults": [],
        "paper": ["-paper"],
        "kitti_yaml": ["-config", os.path.join(source, "config", "kitti.yaml")],
        "synthetic_yaml": ["-config", os.path.join(source, "config", "synthetic.yaml")],
    }
    for what, args in configurations.items():
        printed = msf_config(tool, *args)
        data = check_pyyaml_reads(printed, what)
        check_round_trip(tool, work, printed, data, what)
    # The shipped files, with their comments, are plain YAML.
    for name in ("kitti", "synthetic", "paper"):
        with open(os.path.join(source, "config", name + ".yaml")) as f:
            if not isinstance(yaml.safe_load(f), dict):
                fail("config/%s.yaml is not a map for PyYAML" % name)

    # Values other than the defaults, written by PyYAML (sorted keys, its own number forms).
    edited = {
        "stereo": {"mode": "sgbm_3way", "block_size_px": 7, "guidance_bridge_agreement": 0.375,
                   "disp12_max_diff_px": -3, "left_right_check": True},
        "fusion": {"method": "paper", "lidar_range_sigma_m": 0.0625, "facade_extension": False},
        "tsdf_integrator": {"argmin_tolerance_m": 2.5e-06, "lambda": 5.0, "max_weight": 20000.0, "sweeps": 3,
                            "solve": "argmin"},
        "tsdf_volume": {"voxel_size_m": 0.07, "max_memory_mb": 4096},
        "odometry": {"deskew": "none", "convergence": 1e-05},
        "pipeline": {"queue_capacity": 3},
    }
    path = os.path.join(work, "pyyaml_edited.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(edited, f)
    read = yaml.safe_load(msf_config(tool, "-config", path))
    for section, keys in edited.items():
        for key, value in keys.items():
            if read[section][key] != value:
                fail("%s.%s: PyYAML wrote %r, the project read %r" % (section, key, value, read[section][key]))
    print("PyYAML and msf_config read each other's configuration files")


if __name__ == "__main__":
    main()
