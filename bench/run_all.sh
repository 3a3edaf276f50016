#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# make bench: every benchmark of bench/, on the KITTI sample.
# Usage: bench/run_all.sh BIN_DIR KITTI_DIR
set -euo pipefail
bin=${1:-build/bin} kitti=${2:-../shared/data/kitti}
export MSF_KITTI_DIR="$kitti"
found=0
for b in "$bin"/bench_*; do
  [ -x "$b" ] || continue
  found=1
  echo "== $(basename "$b")"
  "$b" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
done
[ "$found" = 1 ] || echo "bench: no benchmark built yet"
if [ -d "$bin/../python/msfusion" ]; then
  # The interpreter the module was built for (python/CMakeLists.txt: Debian's by default).
  echo "== bench_python.py"
  PYTHONPATH="$bin/../python" "${PYTHON:-/usr/bin/python3}" "$(dirname "$0")/bench_python.py" "$bin" "$kitti" 5
fi
echo "== bench_pipeline.sh"
"$(dirname "$0")/bench_pipeline.sh" "$bin" "$kitti" 5
echo "== bench_reconstruction.sh"
"$(dirname "$0")/bench_reconstruction.sh" "$bin" "$kitti"
echo "== bench_stereo_sigma.sh"
"$(dirname "$0")/bench_stereo_sigma.sh" "$bin" "$kitti"
