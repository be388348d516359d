#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs what the tests need, builds with warnings as errors, runs the whole suite, runs it again
# under ASan+UBSan, then fuzzes the G-code front end. This is what CI runs (.ci/run).
#   scripts/test.sh [--quick]   --quick: only the normal build and suite (no sanitizers, no fuzzing)
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=${OPENCNC_JOBS:-2}
fuzz_seconds=${OPENCNC_FUZZ_SECONDS:-60}

scripts/setup.sh --tests

echo "== build (warnings are errors)"
cmake --preset ci >/dev/null
cmake --build --preset ci -j "$jobs"
echo "== test suite"
ctest --preset ci -j "$jobs"

[[ "${1:-}" == "--quick" ]] && exit 0

echo "== build with AddressSanitizer + UndefinedBehaviorSanitizer"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$jobs"
echo "== test suite under ASan + UBSan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --preset asan -j "$jobs"

if [[ -d fuzz ]] && compgen -G "fuzz/*/CMakeLists.txt" >/dev/null; then
  echo "== fuzzing (${fuzz_seconds}s per target, ASan + UBSan)"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$jobs"
  scripts/fuzz.sh "$fuzz_seconds"
fi
echo "== all tests passed"
