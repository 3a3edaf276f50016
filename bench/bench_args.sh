# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Sourced by the bench scripts: the checks of their arguments, each exiting 1 with a message
# that names the script and what is missing.

# need_tools SCRIPT BIN_DIR TOOL...: every TOOL built in BIN_DIR.
need_tools() {
  local script=$1 bin=$2 tool
  shift 2
  for tool in "$@"; do
    [ -x "$bin/$tool" ] || { echo "$script: no $bin/$tool (build first)" >&2; exit 1; }
  done
}

# need_sequences SCRIPT DIR...: every KITTI sequence folder DIR present.
need_sequences() {
  local script=$1 dir
  shift
  for dir in "$@"; do
    [ -d "$dir" ] || { echo "$script: no KITTI sequence at $dir" >&2; exit 1; }
  done
}

# output_folder: the folder in $out, made; when $out is empty, a temporary one removed at exit.
output_folder() {
  if [ -z "$out" ]; then
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
  fi
  mkdir -p "$out"
}
