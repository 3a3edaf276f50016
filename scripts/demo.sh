#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# make demo: the main job on the built-in default data — msf_reconstruct generates the
# synthetic street (20 frames, with exact ground truth) and reconstructs it.
# Usage: scripts/demo.sh BIN_DIR OUT_DIR
set -euo pipefail
bin=${1:-build/bin} out=${2:-out/demo}
mkdir -p "$(dirname "$out")"
"$bin/msf_reconstruct" -o "$out"
echo "demo: open $out/report.md (mesh: $out/mesh.ply, e.g. pcl_viewer $out/mesh.ply)"
