#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The reference programs of docs/performance.md through the whole controller (`opencnc run` on
# configs/mill-3axis.toml, virtual time) as a Markdown table: motion time, machining time, the
# feed-rate lower bound, contour and following error, limit violations.
# With --lcnc it also runs each program through LinuxCNC 2.9's harness (../shared/tools/lcnc,
# real time: about ten minutes in all) and adds its motion time.
#
#   bench/control/vs_linuxcnc.sh [--lcnc] [--opencnc PATH]
#
# Lower bound: Σ length / programmed feed over the feed moves (`opencnc scan`), plus the rapids
# at √3 × 100 mm/s (all three axes at their limit); acceleration is ignored, so no run can beat it.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../..
opencnc=$root/build/opencnc
lcnc=0
while (($#)); do
  case $1 in
    --lcnc) lcnc=1 ;;
    --opencnc) opencnc=${2:?--opencnc wants a path}; shift ;;
    -h | --help) echo "usage: $0 [--lcnc] [--opencnc PATH]  (the reference programs of docs/performance.md)"; exit 0 ;;
    *) echo "usage: $0 [--lcnc] [--opencnc PATH]" >&2; exit 2 ;;
  esac
  shift
done
shared=$root/../shared
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

python3 "$shared/tools/lcnc/ngc/gen_spiral.py" 20000 "$work/spiral_g64p001.ngc" "G64 P0.01" >/dev/null 2>&1
python3 "$shared/tools/lcnc/ngc/gen_spiral.py" 20000 "$work/spiral_g64p001q0.ngc" "G64 P0.01 Q0" >/dev/null 2>&1
python3 "$root/bench/plan/gen_small_arcs.py" 2000 112.885 "$work/small_arcs.ngc" >/dev/null
programs=(
  "$work/spiral_g64p001.ngc"
  "$work/spiral_g64p001q0.ngc"
  "$shared/tools/lcnc/ngc/square_g64.ngc"
  "$shared/tools/lcnc/ngc/square_g61.ngc"
  /usr/share/linuxcnc/ncfiles/3dtest.ngc
  /usr/share/linuxcnc/ncfiles/arcspiral.ngc
  "$work/small_arcs.ngc"
  "$shared/gcode-corpus/camotics__bear.nc"
)

printf '| program | opencnc motion [s] | machining [s] | LinuxCNC [s] | lower bound [s] | contour [mm] | FE [mm] | violations |\n'
printf '|---|---:|---:|---:|---:|---:|---:|---:|\n'
for p in "${programs[@]}"; do
  name=$(basename "$p")
  "$opencnc" scan "$p" --json --rapid-rate "$(python3 -c 'print(100 * 3 ** 0.5 * 60)')" >"$work/scan.json" 2>/dev/null || true
  "$opencnc" run "$p" --machine "$root/configs/mill-3axis.toml" --report "$work/run.json" >/dev/null 2>&1
  lc="—"
  if ((lcnc)); then
    lc=$("$shared/tools/lcnc/lcnc_motion_time.sh" "$p" --quiet 2>/dev/null | awk '/^MOTION_TIME_S/ {printf "%.3f", $2}')
  fi
  python3 - "$work/scan.json" "$work/run.json" "$name" "$lc" <<'EOF'
import json, sys
scan, run = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
t = scan["time_s"]
bound = (t["feed"] or 0) + (t["rapid"] or 0)
print(f"| {sys.argv[3]} | {run['motion_time_s']:.3f} | {run['machining_time_s']:.3f} | {sys.argv[4]} | {bound:.3f} "
      f"| {run['max_contour_error_mm']:.4f} | {run['max_following_error_mm']:.4f} | {run['limit_violations']} "
      f"|")
EOF
done
