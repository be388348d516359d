# SPDX-License-Identifier: GPL-3.0-or-later
# Sourced by the command-line scenario scripts (tests/cli/*_cli.sh): their two arguments, a fresh
# folder to run in (removed at the end), and `expect`.
#   . tests/cli/cli_harness.sh  (with "$@" = OPENCNC SOURCE_DIR)
case ${1:-} in
  -h | --help) echo "usage: $0 OPENCNC SOURCE_DIR"; exit 0 ;;
  "" | -*) echo "usage: $0 OPENCNC SOURCE_DIR" >&2; exit 2 ;;
esac
B=$1 SRC=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
fail() { echo "FAIL: $*"; exit 1; }
expect() {  # expect EXIT PATTERN command...: the exit code and a line of its output
  want=$1 pattern=$2
  shift 2
  set +e
  out=$("$@" 2>&1)
  rc=$?
  set -e
  printf '%s\n' "$out"
  [ "$rc" -eq "$want" ] || fail "exit $rc, not $want: $*"
  [ "$pattern" = - ] || printf '%s\n' "$out" | grep -Eq -- "$pattern" || fail "no '$pattern' in the output of: $*"
}
