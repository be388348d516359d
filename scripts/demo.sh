#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The main job: installs what is needed, builds, and runs the bundled example on the simulated machine.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --preset default >/dev/null
cmake --build --preset default -j "${OPENCNC_JOBS:-2}" --target opencnc
build/opencnc scan examples/bracket.ngc
