#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# LinuxCNC 2.9's motion time for each program (the harness in ../shared/tools/lcnc, X Y Z at
# 100 mm/s and 1000 mm/s², an MDI `G64 P0.01` before the program), appended to TIMES as
# "PATH<TAB>SECONDS" (FAIL when the harness gave no time) for `jerk_table --lcnc TIMES`.
# Programs already in TIMES are skipped. LinuxCNC runs in real time: a program takes its
# machining time in wall time too.
#   bench/plan/lcnc_times.sh TIMES PROGRAM...
set -u
usage() { echo "usage: $0 TIMES PROGRAM..."; }
case ${1:-} in
  -h | --help) usage; exit 0 ;;
  "" | -*) usage >&2; exit 2 ;;
esac
[ $# -ge 2 ] || { usage >&2; exit 2; }
times=$1
shift
harness=${LCNC_HARNESS:-$(dirname "$0")/../../../shared/tools/lcnc/lcnc_motion_time.sh}
touch "$times"
for p in "$@"; do
  grep -q "^$p	" "$times" && continue
  # --sampler-depth: the default sampler FIFO overflows on long programs with short moves.
  out=$(timeout 7200 "$harness" "$p" --vel 100 --acc 1000 --tol 0.01 --sampler-depth 50000 --quiet 2>/dev/null)
  t=$(echo "$out" | awk '/^MOTION_TIME_S/ {print $2}')
  printf '%s\t%s\n' "$p" "${t:-FAIL}" >> "$times"
done
