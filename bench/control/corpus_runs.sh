#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Every real-world program of ../shared/gcode-corpus that LinuxCNC's rs274 accepts (MANIFEST.tsv:
# "ok", or "ok-with-tools.tbl" with the corpus's tool table) through the whole controller on
# configs/mill-3axis.toml (configs/mill-4axis.toml for the programs with A words) in virtual time: one row per program with its machining time, path
# length, contour error and limit violations, and a last line counting the runs that did not
# finish or touched a limit.
#   bench/control/corpus_runs.sh [--opencnc PATH] [PROGRAM-NAME-FILTER]
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../..
opencnc=$root/build/opencnc
usage() { echo "usage: $0 [--opencnc PATH] [PROGRAM-NAME-FILTER]"; }
filter=
while (($#)); do
  case $1 in
    --opencnc) opencnc=${2:?--opencnc wants a path}; shift ;;
    -h | --help) usage; echo "  runs the accepted corpus programs through the controller (virtual time), one table row each"; exit 0 ;;
    -*) echo "corpus_runs.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
    *) [[ -z $filter ]] || { usage >&2; exit 2; }; filter=$1 ;;
  esac
  shift
done
corpus=$root/../shared/gcode-corpus
report=$(mktemp)
trap 'rm -f "$report"' EXIT
runs=0 bad=0
printf '| program | machining [s] | path [mm] | contour [mm] | violations | result |\n|---|---:|---:|---:|---:|---|\n'
while IFS=$'\t' read -r file _ _ _ _ _ _ _ result; do
  [[ $result == ok || $result == ok-with-tools.tbl ]] || continue
  [[ -z $filter || $file == *$filter* ]] || continue
  profile=mill-3axis
  grep -qiE '^[^(;]*[^a-z(;]a[-+.0-9]' "$corpus/$file" && profile=mill-4axis   # an A word
  args=(--machine "$root/configs/$profile.toml")
  [[ $result == ok-with-tools.tbl ]] && args+=(--set "interpreter.tool_table=$corpus/tools.tbl")
  runs=$((runs + 1))
  if (cd "$corpus" && "$opencnc" run "$file" "${args[@]}" --report "$report" >/dev/null 2>"$report.err"); then
    python3 - "$report" "$file" <<'PY' || bad=$((bad + 1))
import json, sys
r = json.load(open(sys.argv[1]))
ok = r["finished"] and r["limit_violations"] == 0 and not r["limit_touched"]
print(f"| {sys.argv[2]} | {r['machining_time_s']:.3f} | {r['path_length_mm']:.1f} | {r['max_contour_error_mm']:.4f} "
      f"| {r['limit_violations']} | {'finished' if ok else 'NOT OK: ' + str(r.get('fault'))} |")
sys.exit(0 if ok else 1)
PY
  else
    bad=$((bad + 1))
    printf '| %s | | | | | failed: %s |\n' "$file" "$(head -c 200 "$report.err" | tr '\n' ' ')"
  fi
done < <(tail -n +2 "$corpus/MANIFEST.tsv")
rm -f "$report.err"
echo
echo "$runs programs, $bad not finished cleanly"
((bad == 0))
