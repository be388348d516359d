#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs the libFuzzer targets built by the `fuzz` preset (build-fuzz/fuzz/*/fuzz_*), in one of two modes:
#   --gate         deterministic, what scripts/test.sh and CI run: every committed corpus input and
#                  regression input once, then a fixed-seed run of a fixed number of executions, so
#                  that the same commit always passes or always fails;
#   --minutes N    open-ended fuzzing for development: N minutes per target with a random seed; new
#                  inputs are kept in build-fuzz/corpus/<target>, crashes in build-fuzz/artifacts/<target>.
#                  Record the hours and the findings in docs/fuzzing.md; a crash becomes a fix and a
#                  file in fuzz/<area>/regressions/.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/fuzz.sh --gate [--seed N] [--runs M]
       scripts/fuzz.sh --minutes N
  --gate        each target over fuzz/<area>/corpus and fuzz/<area>/regressions, then a fixed-seed run
                of a fixed number of executions (defaults: --seed 1 --runs 20000); deterministic
  --minutes N   open-ended fuzzing, N minutes per target (random seed); new inputs are kept in
                build-fuzz/corpus/<target>, crashes in build-fuzz/artifacts/<target>
  -h, --help    this text
Build the targets first: cmake --preset fuzz && cmake --build --preset fuzz
TXT
}

mode='' minutes='' seed=1 runs=20000
while (($#)); do
  case $1 in
    --gate) mode=gate ;;
    --minutes) mode=open; minutes=${2:-}; shift ;;
    --seed) seed=${2:-}; shift ;;
    --runs) runs=${2:-}; shift ;;
    -h | --help) usage; exit 0 ;;
    *) echo "fuzz.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
number() { [[ $1 =~ ^[0-9]+$ ]]; }
if [[ -z $mode ]]; then usage >&2; exit 2; fi
if [[ $mode == open ]] && ! number "$minutes"; then echo "fuzz.sh: --minutes wants a whole number" >&2; exit 2; fi
if ! number "$seed" || ! number "$runs"; then echo "fuzz.sh: --seed and --runs want whole numbers" >&2; exit 2; fi

targets=()
for target in build-fuzz/fuzz/*/fuzz_*; do
  [[ -x $target ]] && targets+=("$target")
done
if ((${#targets[@]} == 0)); then
  echo "fuzz.sh: no fuzz targets in build-fuzz (cmake --preset fuzz && cmake --build --preset fuzz)" >&2
  exit 2
fi

# Options every run shares: generous timeouts (the machine may be loaded), the area's dictionary.
common() {
  local area=$1
  printf '%s\n' -timeout=25 -rss_limit_mb=2048 -print_final_stats=1
  [[ -f fuzz/$area/$area.dict ]] && printf '%s\n' "-dict=fuzz/$area/$area.dict"
  return 0
}

# The gate's run must not depend on where things are in memory: libFuzzer feeds the values of the
# comparisons it traces (pointers among them) back into its mutations, and some of the code's
# branches depend on addresses, so with address-space randomisation two runs of the same seed
# differ. `setarch -R` turns it off for the run; -reload=0 stops libFuzzer re-reading its output
# folder once a second (which makes the run depend on time).
fixed_layout=()
if setarch "$(uname -m)" -R true 2>/dev/null; then
  fixed_layout=(setarch "$(uname -m)" -R)
elif [[ $mode == gate ]]; then
  echo "fuzz.sh: warning: setarch -R is not permitted here; the gate may differ from run to run" >&2
fi

status=0
for target in "${targets[@]}"; do
  name=$(basename "$target")
  area=$(basename "$(dirname "$target")")
  mapfile -t opts < <(common "$area")
  inputs=("fuzz/$area/corpus")
  [[ -d fuzz/$area/regressions ]] && inputs+=("fuzz/$area/regressions")
  if [[ $mode == gate ]]; then
    work=$(mktemp -d)
    echo "-- $name: ${inputs[*]} once each, then $runs executions with seed $seed"
    # The first folder receives new inputs: a fresh one, so the committed corpus is left as it is
    # and every gate run starts from the same state.
    if ! "$target" "${opts[@]}" -runs=0 -artifact_prefix="$work/" "${inputs[@]}" >"$work/log" 2>&1 ||
       ! "${fixed_layout[@]}" "$target" "${opts[@]}" -reload=0 -seed="$seed" -runs="$runs" \
           -artifact_prefix="$work/" "$work" "${inputs[@]}" >>"$work/log" 2>&1; then
      tail -n 40 "$work/log"
      echo "fuzz: $name failed; the input is in $work (add it to fuzz/$area/regressions once fixed)"
      status=1
      continue
    fi
    grep -E "^#[0-9]+[[:space:]]+DONE" "$work/log" | sed -E 's/exec\/s: [0-9]+ //' || true
    rm -rf "$work"
  else
    corpus=build-fuzz/corpus/$name artifacts=build-fuzz/artifacts/$name
    mkdir -p "$corpus" "$artifacts"
    echo "-- $name: $minutes min, new inputs in $corpus, crashes in $artifacts"
    if ! "$target" "${opts[@]}" -max_total_time=$((minutes * 60)) -artifact_prefix="$artifacts/" \
         "$corpus" "${inputs[@]}" 2>"$artifacts/last.log"; then
      tail -n 40 "$artifacts/last.log"
      echo "fuzz: $name found a problem; the input is in $artifacts"
      status=1
    else
      grep -E "stat::number_of_executed_units|Done" "$artifacts/last.log" | tail -n 2 || true
    fi
  fi
done
exit $status
