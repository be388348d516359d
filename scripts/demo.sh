#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The main job: installs what is needed, builds, and runs the bundled example on the simulated machine.
set -euo pipefail
cd "$(dirname "$0")/.."
case ${1:-} in
  "") ;;
  -h | --help)
    echo "usage: scripts/demo.sh"
    echo "  Installs what is needed (scripts/setup.sh), builds the application and runs examples/bracket.ngc"
    echo "  on the simulated three-axis mill, printing the run's report."
    exit 0 ;;
  *) echo "demo.sh: unknown option '$1' (it takes none; --help says what it does)" >&2; exit 2 ;;
esac
scripts/setup.sh
# The application only: the test and benchmark libraries are installed by `setup.sh --tests`.
cmake --preset default -DOPENCNC_TESTS=OFF -DOPENCNC_BENCH=OFF >/dev/null
cmake --build --preset default -j "${OPENCNC_JOBS:-2}" --target opencnc
# A bracket (pocket, compensated profile, peck-drilled holes) on the simulated three-axis mill:
# interpreted, checked against the soft limits, planned and run in virtual time; the report
# follows (machining time, path length, following and contour error, axis maxima, violations).
build/opencnc run examples/bracket.ngc --machine configs/mill-3axis.toml --unattended
