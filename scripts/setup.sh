#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs the Debian 12 packages opencnc needs (idempotent; apt-get only).
#   scripts/setup.sh            build + run dependencies
#   scripts/setup.sh --tests    also what the test suite needs (clang for fuzzing, LinuxCNC's
#                               rs274 as the conformance oracle and its sample programs)
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libfmt-dev            # formatting
  libcli11-dev          # command line parsing
  nlohmann-json3-dev    # JSON reports and API
  libtomlplusplus-dev   # machine profiles
  libboost-dev          # Boost.Beast (header-only): the HMI server's HTTP and WebSocket
  libeigen3-dev         # least squares of electrode setting's sphere fit (header-only)
  libxml2-dev           # MTConnect: its documents written, `path=` XPaths evaluated (src/connect)
  libmosquitto-dev      # MQTT: the machine's observations published to the shop's broker (src/connect)
  libsqlite3-dev        # the tool store (store::Database), the HMI's history and audit trail, the process-data log
  python3               # helper scripts (program generators, golden regeneration)
)
test_packages=(
  libgtest-dev libgmock-dev   # unit, golden, scenario and fault tests
  liblzma-dev xz-utils        # compressed golden files of the conformance suite
  libbenchmark-dev            # benchmarks
  clang libclang-rt-14-dev    # libFuzzer + sanitizer runtime for the fuzz target
  lld                         # LLVM's linker: the sanitized test binaries link in a third of the time
  linuxcnc-uspace             # rs274 (oracle), /usr/share/linuxcnc/ncfiles; halrun for the HAL tests
  linuxcnc-uspace-dev         # hal.h, rtapi.h: the HAL component opencnc_rt.so (docs/hal.md)
  chromium                    # the HMI's end-to-end tests (headless, driven by playwright-core)
  mosquitto                   # a real MQTT broker the connectivity tests start on loopback
  stress-ng                   # scripts/latency-under-load.sh: CPU, memory and I/O load from other processes
)

usage() {
  cat <<'TXT'
usage: scripts/setup.sh [--tests]
  Installs the Debian 12 packages opencnc needs with apt-get (idempotent; sudo when not root).
  --tests      also what the test suite needs (clang for fuzzing, LinuxCNC's rs274 and its samples)
  -h, --help   this text
TXT
}
while (($#)); do
  case $1 in
    --tests) packages+=("${test_packages[@]}") ;;
    -h | --help) usage; exit 0 ;;
    *) echo "setup.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

# The front end is built with Node.js and npm (scripts/hmi.sh): Debian's, unless the machine has them.
if ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
echo "setup: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
