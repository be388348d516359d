#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Times `opencnc canon` against LinuxCNC's `rs274 -g` on the generated 1,000,000-line program
# (both writing to /dev/null), and `opencnc scan` with its peak memory. CPU time (user+sys) is
# reported beside wall time because the shared machine is often busy. Best of N runs.
# usage: bench/gcode/compare_rs274.sh [OPENCNC] [RUNS] [LINES]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
case ${1:-} in
  -h | --help) echo "usage: $0 [OPENCNC] [RUNS] [LINES]  (opencnc canon/scan against rs274 -g, best of RUNS)"; exit 0 ;;
  -*) echo "compare_rs274.sh: unknown option '$1'; usage: $0 [OPENCNC] [RUNS] [LINES]" >&2; exit 2 ;;
esac
for n in "${2:-5}" "${3:-1}"; do
  case $n in '' | *[!0-9]*) echo "compare_rs274.sh: RUNS and LINES are whole numbers" >&2; exit 2 ;; esac
done
opencnc=${1:-$here/../../build/opencnc}
runs=${2:-5}
lines=${3:-1000000}
prog=${TMPDIR:-/tmp}/opencnc_bench_${lines}.ngc
[ -f "$prog" ] || python3 "$here/gen_program.py" "$prog" "$lines"
echo "program: $prog ($lines lines, $(wc -c < "$prog") bytes)"

tfile=$(mktemp)
trap 'rm -f "$tfile"' EXIT

# best_of NAME CMD...: prints the lowest CPU and wall seconds and the peak RSS over $runs runs
best_of() {
  name=$1; shift
  best_cpu=; best_wall=; rss=
  i=0
  while [ $i -lt "$runs" ]; do
    /usr/bin/time -o "$tfile" -f "%U %S %e %M" "$@" > /dev/null 2> /dev/null
    out=$(tail -1 "$tfile")
    cpu=$(echo "$out" | awk '{printf "%.3f", $1 + $2}')
    wall=$(echo "$out" | awk '{print $3}')
    rss=$(echo "$out" | awk '{print $4}')
    if [ -z "$best_cpu" ] || awk "BEGIN{exit !($cpu < $best_cpu)}"; then best_cpu=$cpu; fi
    if [ -z "$best_wall" ] || awk "BEGIN{exit !($wall < $best_wall)}"; then best_wall=$wall; fi
    i=$((i + 1))
  done
  printf '%-24s cpu %6.3f s   wall %6.3f s   peak RSS %6d KiB\n' "$name" "$best_cpu" "$best_wall" "$rss"
  eval "cpu_$(echo "$name" | tr -c 'a-z0-9\n' '_')=$best_cpu"
}

best_of "rs274 -g" rs274 -g "$prog"
best_of "opencnc canon" "$opencnc" canon "$prog"
best_of "opencnc scan" "$opencnc" scan "$prog"
awk "BEGIN{printf \"canon speed-up over rs274 (cpu): %.1fx\n\", $cpu_rs274__g / $cpu_opencnc_canon}"
awk "BEGIN{printf \"scan: %.2f million lines/s (cpu)\n\", $lines / $cpu_opencnc_scan / 1e6}"
