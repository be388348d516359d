#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs what the tests need, builds everything under ASan+UBSan with warnings as errors, runs
# the whole suite there (the HAL component in halrun too), the HMI's front-end and end-to-end
# tests, then the deterministic fuzz gate. This is what CI runs (.ci/run); --quick is the whole
# suite optimised, without sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/test.sh [--quick]
  Installs the test packages (scripts/setup.sh --tests); builds everything (application, tests,
  benchmarks, the HAL component) under ASan + UBSan with warnings as errors and runs the whole
  suite there (every tenth conformance program; the HAL component in halrun; the breakpoint
  journal's torture, 100 kills); the HMI's front end (scripts/hmi.sh: npm ci, build, vitest, the
  end-to-end test in headless Chromium with the sanitized opencnc, screenshots in
  web/e2e/artifacts); then the fuzz gate (scripts/fuzz.sh --gate: the committed
  corpus, the regression inputs and a fixed-seed run: the same commit always passes or always
  fails). OPENCNC_JOBS sets the cores to use (default 2): the tests run that many at once, the
  builds one more.
  --quick      the optimised build of everything and the whole suite there (all conformance
               programs), and the HMI's tests; no sanitizers, no fuzzing
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
# Builds run one job more than the cores: a link (single-threaded, long for the sanitized test
# binaries) then leaves no core idle. Tests stay at one per core: some of them time real threads.
build_jobs=$((jobs + 1))

scripts/setup.sh --tests

if ((quick)); then
  echo "== build (warnings are errors)"
  cmake --preset ci >/dev/null
  cmake --build --preset ci -j "$build_jobs"
  echo "== test suite"
  ctest --preset ci -j "$jobs"
  echo "== HMI front end: build, unit tests, end to end in headless Chromium"
  scripts/hmi.sh --test --e2e
  exit 0
fi
# CI builds everything once, under the sanitizers, with warnings as errors: the application, the
# tests, the benchmarks, and the HAL component (rtapi_app cannot load an instrumented module: it
# links the real-time core's plain twins, cmake/Sanitizers.cmake). Building the optimised tree as
# well does not fit CI's 15 minutes; `--quick` builds and runs it whole.
echo "== build with AddressSanitizer + UndefinedBehaviorSanitizer (warnings are errors)"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$build_jobs"
fuzz=0
compgen -G "fuzz/*/CMakeLists.txt" >/dev/null && fuzz=1
if ((fuzz)); then
  # The fuzz targets (the G-code libraries again, with clang) build at the lowest priority but one
  # beside the suite and the end-to-end test, which leave a core idle much of the time (tests that
  # wait on timers, the browser, halrun); their log follows the end-to-end test.
  fuzz_log=$(mktemp)
  (cmake --preset fuzz >/dev/null && nice -n 18 cmake --build --preset fuzz -j "$jobs") >"$fuzz_log" 2>&1 &
  fuzz_build=$!
  trap 'kill "$fuzz_build" 2>/dev/null || true; rm -f "$fuzz_log"' EXIT
fi
echo "== test suite under ASan + UBSan"
# Each conformance program forks an instrumented opencnc and rs274 (five minutes for all 615 under
# ASan): every tenth of them runs here and all of them in `--quick`; the interpreter itself runs
# under the sanitizers in its own tests and in the fuzz gate below. Everything else runs whole:
# the HAL component in halrun beside the sanitized controller, the real-time core's symbols, the
# breakpoint journal's torture (100 kills of the writing process).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --preset asan -j "$jobs" -E 'Conformance[.]Program/'
ctest --preset asan -j "$jobs" -R 'Conformance[.]Program/' -I ,,10
echo "== HMI front end: build, unit tests, end to end in headless Chromium (the sanitized opencnc)"
scripts/hmi.sh --test --e2e --opencnc build-asan/opencnc

if ((fuzz)); then
  echo "== fuzz gate (the G-code libraries and the fuzz targets only; ASan + UBSan)"
  built=0
  wait "$fuzz_build" && built=1
  tail -n 3 "$fuzz_log"
  if ((!built)); then
    cat "$fuzz_log"
    echo "test.sh: the fuzz targets did not build" >&2
    exit 1
  fi
  scripts/fuzz.sh --gate
fi
echo "== all tests passed"
