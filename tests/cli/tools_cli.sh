#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# `opencnc tools` and the guard in `opencnc run` on hmc-toolcheck, end to end in a fresh folder:
# import, backup, the typo caught by check (exit 1, its line) and by run (refused, exit 1), wear
# within the band, restore and accept, the 840D export read back exactly, the audit.
#   tests/cli/tools_cli.sh OPENCNC SOURCE_DIR
set -eu
. "$(dirname "$0")/cli_harness.sh"
T="$B tools --db tools.db"
run() { $B run "$SRC/examples/hmc-toolcheck-demo.ngc" --machine "$SRC/configs/hmc-toolcheck.toml" \
  --set "tool_guard.store=\"$dir/tools.db\"" --set tool_changer.sim.prepare_time_s=0.05 \
  --set tool_changer.sim.change_time_s=0.1 --unattended; }

expect 0 "4 tools, 5 edges" $T import "$SRC/configs/hmc-toolcheck.tbl"
expect 1 "no backup" $T check
expect 0 "backup 1 taken" $T backup
expect 0 "matches backup 1" $T check
expect 0 "T5 set" $T set T5 D1 length1=139.225
expect 1 "^T5 D1 length1: backup 193.225, live 139.225 \(-54 mm; geometry tolerance 0.001 mm\)" $T check
expect 1 "^T5 D1 length1: backup 193.225, live 139.225" run
expect 1 '"parameter": "length1"' $T check --json
expect 0 "backup 1 is the live tool table again" $T restore
expect 0 "T3 set" $T set T3 D1 wear_length1=-0.05
expect 0 "matches backup 1" $T check
expect 0 "within tolerance" $T diff
expect 0 "machining time" run
expect 0 "T3 set" $T set T3 D1 radius=4.2
expect 0 "backup 2 taken .*the live values are the backup now" $T accept
expect 0 "matches backup 2" $T check
expect 0 "-" $T export --format 840d -o backup.spf --backup 2
grep -q '^IF (R90==5) AND (R91==2)$' backup.spf || fail "no block for T5 D2"
grep -q '^M17$' backup.spf || fail "no M17"
grep -q 'backup 2 taken' backup.spf || fail "no backup time"
expect 0 "-" $T export --format 840d -o live.spf
expect 0 "4 tools, 5 edges" $B tools --db round.db import backup.spf
expect 0 "-" $B tools --db round.db export --format 840d -o round.spf
tail -n +2 backup.spf >a && tail -n +2 round.spf >b && cmp a b || fail "the 840D export does not read back exactly"
expect 2 "tools.db is the tool store" $T export -o tools.db
expect 0 "T3 D1 radius +4.25 -> 4.2" $T audit --last 3
expect 2 "no parameter 'lenght1'" $T set T5 D1 lenght1=1
expect 2 "-" $T frobnicate
# Checked at the tool change only: the typo holds the run at T3's M6; the operator answers.
printf 'G21 G90\nT1 M6\nG43 H1\nG0 X0 Y0 Z10\nT3 M6\nG43 H3\nG0 Z10\nG1 Z0 F3000\nM2\n' >tc.ngc
runtc() { printf '%s\n' "$1" | $B run tc.ngc --machine "$SRC/configs/hmc-toolcheck.toml" \
  --set "tool_guard.store=\"$dir/tools.db\"" --set 'tool_guard.check="tool-change"' \
  --set tool_changer.sim.prepare_time_s=0.05 --set tool_changer.sim.change_time_s=0.1; }
expect 0 "T3 set" $T set T3 D1 length1=105.25
expect 1 "held before T3 cuts" runtc no
expect 0 "backup 2 is the live tool table again" runtc restore
expect 0 "matches backup 2" $T check
echo "all tools cases passed"
