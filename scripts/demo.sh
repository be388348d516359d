#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The main job: installs what is needed, builds, runs the bracket program on the simulated mill and
# prints the report (or, with --hmi, serves the operator's HMI in the browser with it loaded).
set -euo pipefail
cd "$(dirname "$0")/.."
hmi=0
listen=127.0.0.1:8080
while (($#)); do
  case $1 in
    --hmi) hmi=1 ;;
    --batch) hmi=0 ;;  # the default; kept for scripts that name it
    --listen)
      [[ $# -ge 2 ]] || { echo "demo.sh: --listen needs ADDRESS:PORT" >&2; exit 2; }
      listen=$2
      shift ;;
    -h | --help)
      cat <<'TXT'
usage: scripts/demo.sh [--hmi [--listen ADDRESS:PORT]]
  Installs what is needed (scripts/setup.sh), builds the application and runs examples/bracket.ngc
  on the simulated three-axis mill in virtual time: progress, then the run's report.
  --hmi        instead, also install the front end's npm packages, build the front end and start
               `opencnc serve` on the simulated mill with examples/bracket.ngc loaded: it prints
               the URL (with the operator token) to open in a browser; Ctrl-C stops it
  --listen     where the server listens with --hmi (default 127.0.0.1:8080)
  -h, --help   this text
TXT
      exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (--help says what it takes)" >&2; exit 2 ;;
  esac
  shift
done
scripts/setup.sh
# The application only: the test and benchmark libraries are installed by `setup.sh --tests`.
cmake --preset default -DOPENCNC_TESTS=OFF -DOPENCNC_BENCH=OFF >/dev/null
cmake --build --preset default -j "${OPENCNC_JOBS:-2}" --target opencnc
if ((!hmi)); then
  # A bracket (pocket, compensated profile, peck-drilled holes) on the simulated three-axis mill:
  # interpreted, checked against the soft limits, planned and run in virtual time; the report
  # follows (machining time, path length, following and contour error, axis maxima, violations).
  exec build/opencnc run examples/bracket.ngc --machine configs/mill-3axis.toml --unattended
fi
scripts/hmi.sh
# The simulated mill with its servo on a real-time thread, the bracket program open and checked;
# the URL carries the operator token (also printed); the admin token is in the tokens file named.
exec build/opencnc serve --machine configs/mill-3axis.toml --program examples/bracket.ngc --listen "$listen"
