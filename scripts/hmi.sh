#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The HMI's front end (web/): installs its npm packages from the committed lockfile, builds it
# into web/dist (what `opencnc serve` serves), and runs its tests.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'TXT'
usage: scripts/hmi.sh [--test] [--e2e [--opencnc PATH]]
  Installs the front end's packages (npm ci, from web/package-lock.json) and builds it into
  web/dist (type check, then Vite).
  --test       also its unit tests (vitest)
  --e2e        also the end-to-end test: build/opencnc serve on the simulated mill, driven in
               Debian's headless Chromium (/usr/bin/chromium) by playwright-core: home, open the
               bracket program, run it with hold and resume, find it in the history; then the
               fleet view (opencnc fleet) with two mills publishing to a mosquitto broker, one of
               them killed; screenshots in web/e2e/artifacts (build build/opencnc first)
  --opencnc PATH  the opencnc the end-to-end test serves with (default build/opencnc; CI uses the
               sanitized build-asan/opencnc)
  -h, --help   this text
TXT
}
unit=0
e2e=0
opencnc=build/opencnc
while (($#)); do
  case $1 in
    --test) unit=1 ;;
    --e2e) e2e=1 ;;
    --opencnc)
      [[ $# -ge 2 ]] || { echo "hmi.sh: --opencnc needs a path" >&2; exit 2; }
      opencnc=$2
      shift
      ;;
    -h | --help) usage; exit 0 ;;
    *) echo "hmi.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

opencnc=$(realpath -m "$opencnc")
cd web
# The installed tree is reused while the lockfile is unchanged (npm ci starts from scratch).
stamp=node_modules/.opencnc-lock
if ! cmp -s package-lock.json "$stamp" 2>/dev/null; then
  npm ci --no-audit --no-fund
  cp package-lock.json "$stamp"
fi
npm run --silent build
((unit)) && npx vitest run
if ((e2e)); then
  if [[ ! -x /usr/bin/chromium ]]; then
    echo "hmi.sh: the end-to-end test needs Debian's chromium (scripts/setup.sh --tests)" >&2
    exit 2
  fi
  node e2e/run.mjs --opencnc "$opencnc"
  node e2e/fleet.mjs --opencnc "$opencnc"
fi
