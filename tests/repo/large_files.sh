#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Fails when a file tracked by git is over 1 MiB (generated output committed by mistake; large test
# data is stored xz-compressed). Skips (77) outside a git checkout.
#   tests/repo/large_files.sh SOURCE_DIR
set -eu
case ${1:-} in
  -h | --help) echo "usage: $0 SOURCE_DIR"; exit 0 ;;
  "" | -*) echo "usage: $0 SOURCE_DIR" >&2; exit 2 ;;
esac
limit=1048576
if ! git -C "$1" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "not a git checkout: nothing to check"
  exit 77
fi
cd "$1"
big=$(git ls-files -z | xargs -0 -r stat -c '%s %n' -- 2>/dev/null | awk -v limit=$limit '$1 > limit')
if [ -n "$big" ]; then
  echo "tracked files over 1 MiB (bytes, path):"
  echo "$big"
  exit 1
fi
echo "no tracked file over 1 MiB"
