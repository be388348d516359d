#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs what the tests need, builds with warnings as errors, runs the whole suite and the HMI's
# front-end and end-to-end tests, runs the suite again under ASan+UBSan, then the deterministic fuzz
# gate. This is what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/test.sh [--quick]
  Installs the test packages (scripts/setup.sh --tests), builds with warnings as errors and runs the
  suite; the HMI's front end (scripts/hmi.sh: npm ci, build, vitest, the end-to-end test in headless
  Chromium, screenshots in web/e2e/artifacts); then builds and runs the suite again under ASan + UBSan; then the fuzz gate (scripts/fuzz.sh --gate:
  the committed corpus, the regression inputs and a fixed-seed run: the same commit always passes or
  always fails). OPENCNC_JOBS sets the build's parallel jobs (default 2).
  --quick      only the normal build, the suite and the HMI's tests (no sanitizers, no fuzzing)
  -h, --help   this text
TXT
}

quick=0
while (($#)); do
  case $1 in
    --quick) quick=1 ;;
    -h | --help) usage; exit 0 ;;
    *) echo "test.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

jobs=${OPENCNC_JOBS:-2}

scripts/setup.sh --tests

echo "== build (warnings are errors)"
cmake --preset ci >/dev/null
cmake --build --preset ci -j "$jobs"
echo "== test suite"
ctest --preset ci -j "$jobs"
echo "== HMI front end: build, unit tests, end to end in headless Chromium"
scripts/hmi.sh --test --e2e

((quick)) && exit 0

echo "== build with AddressSanitizer + UndefinedBehaviorSanitizer"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$jobs"
echo "== test suite under ASan + UBSan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --preset asan -j "$jobs"

if compgen -G "fuzz/*/CMakeLists.txt" >/dev/null; then
  echo "== fuzz gate (the G-code libraries and the fuzz targets only; ASan + UBSan)"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$jobs"
  scripts/fuzz.sh --gate
fi
echo "== all tests passed"
