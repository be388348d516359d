#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Every script in scripts/ and bench/ answers --help (exit 0, without doing its work) and refuses an
# option it does not know (exit 2), so that no option is ever taken for a file name.
#   tests/repo/scripts_help.sh SOURCE_DIR
set -u
case ${1:-} in
  -h | --help) echo "usage: $0 SOURCE_DIR"; exit 0 ;;
  "" | -*) echo "usage: $0 SOURCE_DIR" >&2; exit 2 ;;
esac
cd "$1" || exit 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0 checked=0
for script in $(find scripts bench -type f \( -name '*.sh' -o -name '*.py' \) | sort); do
  case $script in *.py) run="python3 $PWD/$script" ;; *) run="bash $PWD/$script" ;; esac
  checked=$((checked + 1))
  # From an empty folder: a script that took an option for a path would leave a file here.
  (cd "$work" && $run --help >/dev/null 2>&1 </dev/null)
  rc=$?
  [ $rc -eq 0 ] || { echo "$script --help: exit $rc, expected 0"; failed=1; }
  (cd "$work" && $run --no-such-option >/dev/null 2>&1 </dev/null)
  rc=$?
  [ $rc -eq 2 ] || { echo "$script --no-such-option: exit $rc, expected 2"; failed=1; }
  if [ -n "$(ls -A "$work")" ]; then
    echo "$script left files behind: $(ls -A "$work")"
    rm -rf "${work:?}"/* "$work"/.[!.]* 2>/dev/null
    failed=1
  fi
done
echo "$checked scripts checked"
exit $failed
