#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The servo thread's wake-up latency while other processes load the CPUs and the memory: starts
# stress-ng (Debian's), runs `opencnc latency --json`, stops the load and prints one JSON object
# with the load, the kernel and the jitter and overruns (docs/performance.md, "Latency under load").
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/latency-under-load.sh [options]
  Measures `opencnc latency` (SCHED_FIFO when allowed) while stress-ng loads the machine, and
  prints {"load": …, "kernel": …, "latency": …} as JSON on stdout.
  --seconds S       how long to measure (default 30)
  --period-us P     servo period in microseconds (default 1000)
  --cpu N           stress-ng CPU workers (default: one per online CPU)
  --vm N            stress-ng memory workers, each touching --vm-bytes (default 2)
  --vm-bytes SIZE   memory per memory worker, stress-ng's syntax (default 256M)
  --io N            stress-ng I/O sync workers (default 1)
  --no-load         measure without load (the baseline)
  --opencnc PATH    the opencnc binary (default build/opencnc)
  -h, --help        this text
TXT
}

seconds=30
period_us=1000
cpu_workers=$(getconf _NPROCESSORS_ONLN)
vm_workers=2
vm_bytes=256M
io_workers=1
load=1
opencnc=build/opencnc
number() { [[ $2 =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "latency-under-load.sh: $1 needs a number, not '$2'" >&2; exit 2; }; }
while (($#)); do
  case $1 in
    --seconds) number "$1" "${2-}"; seconds=$2; shift ;;
    --period-us) number "$1" "${2-}"; period_us=$2; shift ;;
    --cpu) number "$1" "${2-}"; cpu_workers=$2; shift ;;
    --vm) number "$1" "${2-}"; vm_workers=$2; shift ;;
    --vm-bytes) [[ ${2-} =~ ^[0-9]+[KMGkmg%]?$ ]] || { echo "latency-under-load.sh: --vm-bytes needs a size like 256M" >&2; exit 2; }
      vm_bytes=$2; shift ;;
    --io) number "$1" "${2-}"; io_workers=$2; shift ;;
    --no-load) load=0 ;;
    --opencnc) opencnc=${2-}; [[ -n $opencnc ]] || { echo "latency-under-load.sh: --opencnc needs a path" >&2; exit 2; }; shift ;;
    -h | --help) usage; exit 0 ;;
    *) echo "latency-under-load.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
[[ -x $opencnc ]] || { echo "latency-under-load.sh: $opencnc is not an executable (build it first)" >&2; exit 2; }

stress_pid=
stop_load() {
  if [[ -n $stress_pid ]]; then
    kill -TERM "$stress_pid" 2>/dev/null || true
    wait "$stress_pid" 2>/dev/null || true
    stress_pid=
  fi
}
trap stop_load EXIT INT TERM

if ((load)); then
  command -v stress-ng >/dev/null || { echo "latency-under-load.sh: stress-ng is missing (scripts/setup.sh --tests installs it)" >&2; exit 2; }
  # Longer than the measurement; stopped as soon as it ends.
  stress-ng --cpu "$cpu_workers" --vm "$vm_workers" --vm-bytes "$vm_bytes" --io "$io_workers" \
    --timeout "$(( ${seconds%.*} + 60 ))s" --quiet >/dev/null 2>&1 &
  stress_pid=$!
  sleep 2  # the workers start and reach their load before the measurement does
  kill -0 "$stress_pid" 2>/dev/null || { echo "latency-under-load.sh: stress-ng did not start" >&2; exit 1; }
fi

latency=$("$opencnc" latency --seconds "$seconds" --period-us "$period_us" --json 2>/dev/null)
stop_load

kernel=$(uname -r)
preempt_rt=false
if uname -v | grep -q 'PREEMPT_RT'; then preempt_rt=true; fi
printf '{"load": {"on": %s, "cpu_workers": %s, "vm_workers": %s, "vm_bytes": "%s", "io_workers": %s, "cpus": %s}, ' \
  "$( ((load)) && echo true || echo false)" "$cpu_workers" "$vm_workers" "$vm_bytes" "$io_workers" "$(getconf _NPROCESSORS_ONLN)"
printf '"kernel": {"release": "%s", "preempt_rt": %s}, "latency": %s}\n' "$kernel" "$preempt_rt" "$latency"
