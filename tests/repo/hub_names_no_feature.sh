#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The hub knows no machine: `grep -ci 'edm\|coupl\|broach\|electrode\|plasma\|torch'` over the hub's sources
# (src/controller, include/opencnc/controller) finds nothing but comments. A feature's words belong
# in its own folder, reached through the hub's extension points (docs/code-overview.md).
#
#   hub_names_no_feature.sh SOURCE_DIR
set -eu
case "${1:-}" in
  -h | --help) echo "usage: $0 SOURCE_DIR  (the hub's sources name no machine feature but in comments)"; exit 0 ;;
  "" | -*) echo "usage: $0 SOURCE_DIR" >&2; exit 2 ;;
esac
root=$1
hub="$root/src/controller $root/include/opencnc/controller"
# Every line that names a feature, less those whose words are all in a // comment.
found=$(grep -rni 'edm\|coupl\|broach\|electrode\|plasma\|torch' $hub | grep -v '^[^:]*:[0-9]*: *//' || true)
if [ -n "$found" ]; then
  echo "the hub names a machine feature outside comments (move it into the feature's folder):"
  echo "$found"
  exit 1
fi
files=$(find $hub -name '*.[ch]pp' | wc -l)
total=$(cat $(find $hub -name '*.[ch]pp') | grep -ci 'edm\|coupl\|broach\|electrode\|plasma\|torch' || true)
echo "the hub's $files files name no machine feature but in $total comment lines"
