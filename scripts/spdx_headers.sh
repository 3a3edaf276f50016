#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# The one-line copyright and licence header of every source file (LICENSE: BSD-3-Clause), in its
# first line, or its second after a #! line.
#   scripts/spdx_headers.sh --check   lists the files without it; exit 1 when there are any
#   scripts/spdx_headers.sh --add     adds it to them
set -euo pipefail
cd "$(dirname "$0")/.."
readonly TEXT="Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause"

sources() {
  git ls-files -- '*.cpp' '*.h' '*.hpp' '*.py' '*.sh' '*.cmake' '*.in' '*CMakeLists.txt' Makefile .ci/run
}
comment() {
  case "$1" in *.cpp | *.h | *.hpp | *.h.in) echo "//" ;; *) echo "#" ;; esac
}
lacking() {
  sources | while read -r f; do head -n 2 "$f" | grep -qF "$TEXT" || echo "$f"; done
}

case "${1:-}" in
--check)
  missing=$(lacking)
  [ -z "$missing" ] && exit 0
  echo "files without the line '$TEXT':"
  echo "$missing"
  exit 1
  ;;
--add)
  lacking | while read -r f; do
    line="$(comment "$f") $TEXT"
    if head -n 1 "$f" | grep -q '^#!'; then
      sed -i "1a $line" "$f"
    else
      sed -i "1i $line" "$f"
    fi
  done
  ;;
*)
  echo "usage: $0 --check | --add" >&2
  exit 2
  ;;
esac
