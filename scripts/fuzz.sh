#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs every libFuzzer target built by the `fuzz` preset for N seconds (default 60) on its seed corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
status=0
for target in build-fuzz/fuzz/*/fuzz_*; do
  [[ -x "$target" ]] || continue
  name=$(basename "$target")
  area=$(basename "$(dirname "$target")")
  seeds="fuzz/$area/corpus"
  dict=()
  [[ -f "fuzz/$area/$area.dict" ]] && dict=(-dict="fuzz/$area/$area.dict")
  work=$(mktemp -d)
  echo "-- $name: ${seconds}s, seeds from $seeds"
  if ! "$target" "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$work/" "$work" "$seeds" 2>"$work/log"; then
    tail -n 40 "$work/log"
    echo "fuzz: $name found a problem; artifacts in $work"
    status=1
  else
    grep -E "stat::number_of_executed_units|Done" "$work/log" | tail -n 2 || true
  fi
done
exit $status
