#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The HAL component's cost and its thread's jitter on this machine: loads tests/hal/loopback.hal
# (opencnc_rt, a lag per joint) with timedelta on the servo thread, runs tests/hal/long_move.ngc with
# `opencnc run --hal`, then prints opencnc.update's time/tmax (HAL counts CPU cycles in uspace: the
# CPU's MHz converts them) and timedelta's figures (ns). docs/performance.md quotes it.
#   bench/hal/hal_costs.sh BUILD_DIR
set -eu
case ${1:-} in
  -h | --help) echo "usage: $0 BUILD_DIR   (opencnc_rt.so installed in /usr/lib/linuxcnc/modules: docs/hal.md)"; exit 0 ;;
  "" | -*) echo "usage: $0 BUILD_DIR" >&2; exit 2 ;;
esac
build=$(cd "$1" && pwd)
src=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
chmod 777 "$work"
trap 'halrun -U >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
if [ "$(id -u)" = 0 ]; then RTAPI_UID=${RTAPI_UID:-$(id -u nobody)}; export RTAPI_UID; fi
RTAPI_FIFO_PATH=$work/fifo
export RTAPI_FIFO_PATH
halrun -U >/dev/null 2>&1 || true
/usr/lib/linuxcnc/realtime start >"$work/log" 2>&1
sed 's/heartbeat_ms=100/heartbeat_ms=100 shm=\/opencnc-bench/' "$src/tests/hal/loopback.hal" | sed '/^start$/d' >"$work/costs.hal"
printf 'loadrt timedelta count=1\naddf timedelta.0 servo-thread\nstart\n' >>"$work/costs.hal"
halcmd -f "$work/costs.hal" >>"$work/log" 2>&1
"$build/opencnc" run "$src/tests/hal/long_move.ngc" --machine "$src/configs/mill-3axis.toml" --hal \
  --hal-shm /opencnc-bench --unattended >/dev/null
halcmd setp opencnc.update.tmax 0 >>"$work/log" 2>&1 || true
"$build/opencnc" run "$src/tests/hal/long_move.ngc" --machine "$src/configs/mill-3axis.toml" --hal \
  --hal-shm /opencnc-bench --unattended >/dev/null
mhz=$(awk -F: '/cpu MHz/ { print $2; exit }' /proc/cpuinfo)
echo "cpu MHz: $mhz"
halcmd show param opencnc.update 2>/dev/null | grep -E 'time|tmax' || true
halcmd show pin opencnc.update 2>/dev/null | grep -E 'time|tmax' || true
halcmd show pin timedelta.0 2>/dev/null | grep -E 'jitter|max|min|err|out' || true
halcmd show param servo-thread 2>/dev/null | grep -E 'time|tmax' || true
halcmd show pin servo-thread 2>/dev/null | grep -E 'time|tmax' || true
