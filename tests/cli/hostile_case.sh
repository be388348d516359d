#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# One row of hostile-inputs.tsv: runs its command in a fresh folder, then checks the exit code, the
# output (stdout and stderr together) against the row's pattern and runs the row's after-check.
# Exit 77 with a line starting SKIP: the case does not apply to this build (ctest shows it skipped).
#   tests/cli/hostile_case.sh OPENCNC SOURCE_DIR TABLE NAME
# The command sees $B (the opencnc binary), $SRC (the source tree), $M (configs/mill-3axis.toml),
# $E (examples/bracket.ngc), $S (a 100 mm square, tests/scenario/programs/square.ngc), $Q (a 20 mm
# move, 0.25 s of machining: a quick run where any run will do).
set -u
case ${1:-} in
  -h | --help) echo "usage: $0 OPENCNC SOURCE_DIR TABLE NAME"; exit 0 ;;
  "" | -*) echo "usage: $0 OPENCNC SOURCE_DIR TABLE NAME" >&2; exit 2 ;;
esac
B=$1 SRC=$2 table=$3 name=$4
M=$SRC/configs/mill-3axis.toml E=$SRC/examples/bracket.ngc S=$SRC/tests/scenario/programs/square.ngc
export B SRC M E S
row=$(awk -F'\t' -v n="$name" '$1 == n' "$table")
[ -n "$row" ] || { echo "no row '$name' in $table"; exit 2; }
want_exit=$(printf '%s' "$row" | cut -f2)
pattern=$(printf '%s' "$row" | cut -f3)
command=$(printf '%s' "$row" | cut -f4)
check=$(printf '%s' "$row" | cut -f5)

work=$(mktemp -d) fixtures=$(mktemp -d)
trap 'chmod -R u+w "$work" 2>/dev/null; rm -rf "$work" "$fixtures"' EXIT
Q=$fixtures/quick.ngc
printf 'G21 G90 G94\nG1 X20 F6000\nM2\n' > "$Q"
export Q
cd "$work" || exit 2
out=$(sh -c "$command" 2>&1)
rc=$?
printf '%s\n-- exit %s\n' "$out" "$rc"
# A command may skip itself (exit 77 and a line starting with SKIP), e.g. a memory limit under ASan.
if [ "$rc" = 77 ] && printf '%s' "$out" | grep -q '^SKIP'; then exit 77; fi
failed=0
[ "$rc" = "$want_exit" ] || { echo "FAIL: exit $rc, expected $want_exit"; failed=1; }
if [ -n "$pattern" ] && [ "$pattern" != "-" ] && ! printf '%s' "$out" | grep -qE -- "$pattern"; then
  echo "FAIL: the output does not match: $pattern"
  failed=1
fi
if [ -n "$check" ] && [ "$check" != "-" ] && ! sh -c "$check"; then
  echo "FAIL: the check after the run failed: $check"
  failed=1
fi
exit $failed
