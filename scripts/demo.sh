#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The main job: installs what is needed, builds, and serves the operator's HMI on the simulated
# mill with the bracket program loaded (or, with --batch, runs it and prints the report).
set -euo pipefail
cd "$(dirname "$0")/.."
batch=0
listen=127.0.0.1:8080
while (($#)); do
  case $1 in
    --batch) batch=1 ;;
    --listen)
      [[ $# -ge 2 ]] || { echo "demo.sh: --listen needs ADDRESS:PORT" >&2; exit 2; }
      listen=$2
      shift ;;
    -h | --help)
      cat <<'TXT'
usage: scripts/demo.sh [--batch] [--listen ADDRESS:PORT]
  Installs what is needed (scripts/setup.sh, the front end's npm packages), builds the application
  and the front end, and starts `opencnc serve` on the simulated three-axis mill with
  examples/bracket.ngc loaded: it prints the URL (with the operator token) to open in a browser;
  Ctrl-C stops it.
  --batch      instead, run examples/bracket.ngc on the simulated mill in virtual time and print
               the run's report (no browser)
  --listen     where the server listens (default 127.0.0.1:8080)
  -h, --help   this text
TXT
      exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (--help says what it takes)" >&2; exit 2 ;;
  esac
  shift
done
scripts/setup.sh
# The application only (the test and benchmark libraries are installed by `setup.sh --tests`),
# optimised without debug information: the first build on two cores is what a newcomer waits for.
cmake --preset demo >/dev/null
cmake --build --preset demo -j "${OPENCNC_JOBS:-2}" --target opencnc
if ((batch)); then
  # A bracket (pocket, compensated profile, peck-drilled holes) on the simulated three-axis mill:
  # interpreted, checked against the soft limits, planned and run in virtual time; the report
  # follows (machining time, path length, following and contour error, axis maxima, violations).
  exec build/opencnc run examples/bracket.ngc --machine configs/mill-3axis.toml --unattended
fi
scripts/hmi.sh
# The simulated mill with its servo on a real-time thread, the bracket program open and checked;
# the URL carries the operator token (also printed); the admin token is in the tokens file named.
exec build/opencnc serve --machine configs/mill-3axis.toml --program examples/bracket.ngc --listen "$listen"
