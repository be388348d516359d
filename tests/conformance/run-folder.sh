#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Compares opencnc with rs274 on every G-code program below a folder that is not part of this
# suite (LinuxCNC's own tests/interp, held out from it; a customer's programs): each program runs
# in its own folder through tests/gcode/diff_rs274.py (motion subset within 1e-4, exit status, the
# problem of a rejected program). Prints one line per program that differs and the counts.
#
# Usage: tests/conformance/run-folder.sh [--opencnc PATH] [--skip REGEX] FOLDER
#   --opencnc PATH   the binary under test (default: build/opencnc of this worktree)
#   --skip REGEX     leave out programs whose path (relative to FOLDER) matches (grep -E)
# Exit status: 0 if every program matches, 1 if any differs, 2 on a usage error.
set -euo pipefail
export LC_ALL=C

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
opencnc=$repo/build/opencnc
skip=
usage() { sed -n '3,11p' "$0" | sed 's/^# \{0,1\}//'; }
while (($#)); do
  case $1 in
    --opencnc) opencnc=${2:?--opencnc needs a path}; shift 2 ;;
    --skip) skip=${2:?--skip needs a pattern}; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    -*) echo "run-folder: unknown option $1" >&2; usage >&2; exit 2 ;;
    *) break ;;
  esac
done
(($# == 1)) || { usage >&2; exit 2; }
folder=$(cd "$1" && pwd)
[[ -x $opencnc ]] || { echo "run-folder: $opencnc is not an executable" >&2; exit 2; }
opencnc=$(cd "$(dirname "$opencnc")" && pwd)/$(basename "$opencnc")
command -v rs274 >/dev/null || { echo "run-folder: rs274 not found (install LinuxCNC 2.9)" >&2; exit 2; }

total=0 same=0
while IFS= read -r -d '' file; do
  rel=${file#"$folder"/}
  if [[ -n $skip ]] && grep -Eq "$skip" <<<"$rel"; then continue; fi
  total=$((total + 1))
  if line=$(cd "$(dirname "$file")" &&
              timeout 60 python3 "$repo/tests/gcode/diff_rs274.py" --opencnc "$opencnc" "$(basename "$file")" 2>&1); then
    same=$((same + 1))
  else
    echo "DIFF $rel: $(head -n 1 <<<"$line")"
  fi
done < <(find "$folder" -name '*.ngc' -print0 | sort -z)
echo "$same of $total programs match rs274"
((same == total))
