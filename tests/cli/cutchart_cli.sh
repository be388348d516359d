#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# `opencnc cutchart` and the chart in `opencnc run` on the simulated plasma table, end to end
# in a fresh folder: import, a bad CSV refused at file:line:col with nothing changed, set and the
# audit, the export read back equal and never written over the store, a program's unknown material
# an error and its feed a warning at the line (opencnc run's preflight), examples/plasma-cutchart.ngc cut.
#   tests/cli/cutchart_cli.sh OPENCNC SOURCE_DIR
set -eu
. "$(dirname "$0")/cli_harness.sh"
C="$B cutchart --db chart.db"

expect 2 "import CHART.csv. creates a cut chart" $C list
expect 0 "4 materials are the cut chart now" $C import "$SRC/configs/plasma-cutchart.csv"
expect 0 "Mild steel 10 mm 45 A" $C list
before=$($C list --json)
sed 's/^6,Mild steel 6 mm 45 A,6,plasma,1.5,2400/6,Mild steel 6 mm 45 A,6,plasma,1.5,fast/' \
  "$SRC/configs/plasma-cutchart.csv" > bad.csv
expect 1 "^bad.csv:8:37: error: feed_mm_min: \"fast\" is not a number" $C import bad.csv
[ "$($C list --json)" = "$before" ] || fail "a refused import changed the chart"
expect 1 "cut_height_mm: 5 is above the pierce height 3.8 \(nothing changed\)" $C set 6 cut_height_mm=5
expect 0 "material 6 set" $C set 6 feed_mm_min=2500
expect 0 "command line +set +material 6 feed_mm_min +2400 -> 2500" $C audit --last 1
expect 0 "-" $C export -o chart.csv
expect 2 "-" $C export -o chart.db
$C show 6 > /dev/null
expect 0 "4 materials" $B cutchart --db again.db import chart.csv
[ "$($B cutchart --db again.db list --json)" = "$($C list --json)" ] || fail "the export did not read back equal"

{ cat "$SRC/configs/plasma-table.toml"; printf '\n[cut_chart]\nstore = "chart.db"\n'; } > table.toml
expect 0 "Mild steel 3 mm" $B cutchart --machine table.toml list
printf 'G21 G90\nG0 Z15\nM194 P99\nG0 X90 Y90\nM190\nG1 X100 F2400\nM191\nM2\n' > bad.ngc
expect 1 "bad.ngc:3:1: error: M194: material 99 is not in the cut chart" $B run bad.ngc --machine table.toml
printf 'G21 G90\nG0 Z15\nM194 P6\nG0 X90 Y90\nM190\nG1 X100 F3200\nM191\nM2\n' > fast.ngc
expect 0 "fast.ngc:6:9: warning: the feed 3200 mm/min is faster than cut chart material 6's 2500" \
  $B run fast.ngc --machine table.toml
expect 0 "pierces" $B run "$SRC/examples/plasma-cutchart.ngc" --machine table.toml --report r.json
echo "all cutchart cases passed"
