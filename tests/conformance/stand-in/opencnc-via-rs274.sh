#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A stand-in for the opencnc binary that speaks the command-line contract the conformance harness
# uses (docs/conformance.md) and answers with LinuxCNC's rs274. It checks the harness end to end
# through the same path the real opencnc will take:
#   OPENCNC_CONFORMANCE_BINARY=tests/conformance/stand-in/opencnc-via-rs274.sh build/tests/conformance/conformance_tests
# Supports `canon` and `check` with --tool-table and --subroutine-path; no --dialect (rs274 has none).
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
sub=${1:-}
shift || true
case $sub in
  canon | check) ;;
  *) echo "usage: $0 canon|check FILE [--tool-table T] [--subroutine-path DIR]..." >&2; exit 2 ;;
esac
if [[ ${1:-} == --help ]]; then
  printf 'Usage: opencnc %s [OPTIONS] FILE\nOptions:\n  --tool-table FILE\n  --subroutine-path DIR ...\n' "$sub"
  exit 0
fi
file=${1:?no FILE}
shift
args=()
paths=()
while (($#)); do
  case $1 in
    --tool-table) args+=(-t "$2"); shift 2 ;;
    --subroutine-path) paths+=("$2"); shift 2 ;;
    *) echo "$file: error: option $1 not supported by the rs274 stand-in" >&2; exit 2 ;;
  esac
done
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
# The first search-path entry is the program's folder, which rs274 searches as its working folder.
if ((${#paths[@]} > 1)); then
  printf '[RS274NGC]\nSUBROUTINE_PATH = %s\n' "$(IFS=:; echo "${paths[*]:1}")" >"$home/run.ini"
  args+=(-i "$home/run.ini")
fi
HOME=$home rs274 "${args[@]}" -g "$file" </dev/null >"$home/out" 2>"$home/err"
rc=$?
[[ $sub == canon ]] && cat "$home/out"
if ((rc != 0)); then
  message=$(grep -v -x executing "$home/err" | head -n 1)
  code=$(MSG="$message" awk -F'\t' '!/^#/ && NF >= 2 && ENVIRON["MSG"] ~ $1 { print $2; exit }' "$here/error-codes.tsv")
  echo "$file: error: $message [$code]" >&2
  exit 1
fi
exit 0
