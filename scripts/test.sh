#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs what the tests need, builds with warnings as errors, runs the HAL tests and the HMI's
# front-end and end-to-end tests, the whole suite under ASan+UBSan, then the deterministic fuzz
# gate. This is what CI runs (.ci/run); --quick is the whole suite without sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/test.sh [--quick]
  Installs the test packages (scripts/setup.sh --tests); builds the application, the HAL component
  and the benchmarks optimised with warnings as errors and runs the HAL tests in halrun and the
  breakpoint journal's torture (100 kills); the HMI's
  front end (scripts/hmi.sh: npm ci, build, vitest, the end-to-end test in headless Chromium,
  screenshots in web/e2e/artifacts); then builds the whole suite under ASan + UBSan and runs it
  (every tenth conformance program); then the fuzz gate (scripts/fuzz.sh --gate: the committed
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

echo "== build (warnings are errors)"
cmake --preset ci >/dev/null
if ((quick)); then
  cmake --build --preset ci -j "$build_jobs"
  echo "== test suite"
  ctest --preset ci -j "$jobs"
  echo "== HMI front end: build, unit tests, end to end in headless Chromium"
  scripts/hmi.sh --test --e2e
  exit 0
fi
# The whole suite is built and run once, under the sanitizers, below: the suite's tests pass in both
# builds (`--quick` runs it here), and building the tests twice does not fit CI's 15 minutes. This
# build makes everything else with the optimiser and warnings as errors: the application, the HAL
# component and the benchmarks; then the tests that need this build: the HAL component in halrun
# (a sanitised module cannot load into rtapi_app), the real-time core's symbol check, and the
# breakpoint journal's torture (100 kills of the writing process; its benchmark, optimised).
cmake --build --preset ci -j "$build_jobs" --target src/all apps/opencnc/all bench/all
echo "== the HAL component in halrun, the real-time core's symbols, the journal's torture (optimised build)"
ctest --preset ci -j "$jobs" -R '^(hal|repo|bench)[.]'
echo "== HMI front end: build, unit tests, end to end in headless Chromium"
scripts/hmi.sh --test --e2e

echo "== build with AddressSanitizer + UndefinedBehaviorSanitizer"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$build_jobs"
echo "== test suite under ASan + UBSan"
# Each conformance program forks an instrumented opencnc and rs274 (five minutes for all 615 under
# ASan): every tenth of them runs here and all of them in `--quick`; the interpreter itself runs
# under the sanitizers in its own tests and in the fuzz gate below. Everything else runs whole.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --preset asan -j "$jobs" -E 'Conformance[.]Program/'
ctest --preset asan -j "$jobs" -R 'Conformance[.]Program/' -I ,,10

if compgen -G "fuzz/*/CMakeLists.txt" >/dev/null; then
  echo "== fuzz gate (the G-code libraries and the fuzz targets only; ASan + UBSan)"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$build_jobs"
  scripts/fuzz.sh --gate
fi
echo "== all tests passed"
