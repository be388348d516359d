#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# The servo tick in LinuxCNC's HAL (opencnc_rt.so) driving a loopback machine (loopback.hal), with
# `opencnc run --hal` as the controller. Exits 77 (ctest: skipped, with the reason printed) when
# halrun or the component is missing; never passes silently.
"""usage: hal_tests.py TEST OPENCNC COMPONENT SOURCE_DIR

TEST is one of:
  same-as-virtual  the commanded positions at the pins equal, period by period, those of the same
                   program in virtual time (opencnc run --trace)
  safety-pins      e-stop, amplifier fault and limit switch set from halcmd mid-motion: the drive
                   enable falls within one servo period
  kill-controller  the controller killed (SIGKILL) mid-motion: the axis stops within its limits
                   (heartbeat timeout, then the abort deceleration) and the drives are disabled;
                   then a new controller attaches to the tick that outlived it (same set-up),
                   resets the fault and runs a program to the end"""
import csv
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SKIP = 77
MODULES = Path("/usr/lib/linuxcnc/modules")
REALTIME = "/usr/lib/linuxcnc/realtime"
PERIOD_S = 0.001
SHM = "/opencnc-test"


class Hal:
    """rtapi_app with loopback.hal loaded; halsampler recording; torn down on exit."""

    def __init__(self, source_dir, work):
        self.env = dict(os.environ)
        if os.geteuid() == 0:  # rtapi_app refuses root without a user to fall back to
            self.env.setdefault("RTAPI_UID", str(int(subprocess.check_output(["id", "-u", "nobody"]))))
        work.chmod(0o777)  # rtapi_app, as that user, binds its socket here
        self.env["RTAPI_FIFO_PATH"] = str(work / "rtapi_fifo")
        self.work = work
        self.run(["halrun", "-U"], check=False)
        self.run([REALTIME, "start"])  # the rtapi_app master (what halrun starts first)
        text = (source_dir / "tests/hal/loopback.hal").read_text().replace(
            "heartbeat_ms=100", f"heartbeat_ms=100 shm={SHM}")
        (work / "loopback.hal").write_text(text)
        loaded = self.run(["halcmd", "-f", str(work / "loopback.hal")], check=False)
        if loaded.returncode != 0:
            self.close()
            raise RuntimeError("halcmd -f loopback.hal failed:\n" + loaded.stdout)
        self.samples_path = work / "samples.txt"
        self.sampler = subprocess.Popen(["stdbuf", "-oL", "halsampler", "-c", "0"], stdout=open(self.samples_path, "w"),
                                        stderr=subprocess.DEVNULL, env=self.env)

    def run(self, args, check=True):
        # Output to a file, not a pipe: the rtapi_app that halcmd may start keeps it open for good.
        log = self.work / "hal.log"
        with open(log, "a") as out:
            start = out.tell()
            done = subprocess.run(args, env=self.env, stdout=out, stderr=subprocess.STDOUT, timeout=60)
        done.stdout = log.read_text()[start:]
        if check and done.returncode != 0:
            raise RuntimeError(f"{' '.join(args)} failed:\n{done.stdout}")
        return done

    def sets(self, signal_name, value):
        self.run(["halcmd", "sets", signal_name, value])

    def samples(self):
        """Rows of (x, y, z, x_enable, estop_ok, amp_fault, limit_max) read so far."""
        rows = []
        for line in self.samples_path.read_text().splitlines():
            f = line.split()
            if len(f) == 7 and "\0" not in line:
                rows.append([float(v) for v in f[:3]] + [int(v) for v in f[3:]])
        return rows

    def close(self):
        time.sleep(0.2)
        if getattr(self, "sampler", None) is not None:
            self.sampler.terminate()
            self.sampler.wait(timeout=10)
            self.sampler = None
        self.run([REALTIME, "stop"], check=False)
        self.run(["halrun", "-U"], check=False)


def controller(opencnc, source_dir, program, work, extra=()):
    args = [str(opencnc), "run", str(source_dir / "tests/hal" / program), "--machine",
            str(source_dir / "configs/mill-3axis.toml"), "--hal", "--hal-shm", SHM, "--unattended", *extra]
    return subprocess.Popen(args, stdout=open(work / "run.out", "w"), stderr=subprocess.STDOUT)


def moving(rows):
    """Index of the first sample whose commanded position left the start (0, 0, 0: the profile's
    immediate homing at 0, where both machines power up)."""
    return next(i for i, r in enumerate(rows) if any(v != 0.0 for v in r[:3]))


def wait_for_motion(hal, before, seconds=30.0):
    """Waits until X moves in the samples after `before` (a controller under the sanitizers, on a
    busy machine, takes seconds to start), so that what follows happens mid-motion."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        xs = [r[0] for r in hal.samples()[before:]]
        if any(b != a for a, b in zip(xs, xs[1:])):
            return True
        time.sleep(0.05)
    return False


def same_as_virtual(opencnc, source_dir, hal, work):
    trace = work / "virtual.csv"
    subprocess.run([str(opencnc), "run", str(source_dir / "tests/hal/move.ngc"), "--machine",
                    str(source_dir / "configs/mill-3axis.toml"), "--trace", str(trace), "--unattended"],
                   check=True, stdout=subprocess.DEVNULL)
    with open(trace) as f:
        virtual = [[float(r["out_X"]), float(r["out_Y"]), float(r["out_Z"])] for r in csv.DictReader(f)]
    run = controller(opencnc, source_dir, "move.ngc", work)
    code = run.wait(timeout=60)
    print((work / "run.out").read_text())
    if code != 0:
        return fail(f"opencnc run --hal exited {code}")
    rows = hal.samples()
    v0, h0 = moving(virtual), moving(rows)
    vm = virtual[v0:]
    hm = [r[:3] for r in rows[h0:h0 + len(vm)]]
    if len(hm) < len(vm):
        return fail(f"HAL samples end after {len(hm)} of the {len(vm)} virtual periods")
    worst = max(abs(a - b) for v, h in zip(vm, hm) for a, b in zip(v, h))
    if os.environ.get("OPENCNC_HAL_DEBUG"):
        for i in range(0, len(vm), 100):
            print(i, vm[i], hm[i])
    print(f"{len(vm)} periods of motion compared; largest difference {worst:.2e} mm")
    return 0 if worst <= 1.5e-6 else fail("the commanded positions differ from virtual time")


def reaction(hal, signal_name, value, column, opencnc, source_dir, work):
    before = len(hal.samples())
    run = controller(opencnc, source_dir, "long_move.ngc", work)
    if not wait_for_motion(hal, before):
        return fail(f"{signal_name}: the program never moved X")
    time.sleep(0.5)
    hal.sets(signal_name, value)
    run.wait(timeout=30)
    time.sleep(0.2)
    rows = hal.samples()[before:]
    toggled = next(i for i, r in enumerate(rows) if r[column] == (1 if value == "true" else 0) and i > 0)
    disabled = next((i for i in range(toggled - 1, len(rows)) if rows[i][3] == 0), None)
    if disabled is None:
        return fail(f"{signal_name}: the drive stayed enabled")
    late = disabled - toggled
    print(f"{signal_name} set in period {toggled}: enable low in period {disabled} ({late} later)")
    return 0 if late <= 1 else fail(f"{signal_name}: {late} periods to disable the drive (one allowed)")


def safety_pins(opencnc, source_dir, hal, work):
    for name, value, column, reset in (("estop-ok", "false", 4, "true"), ("x-amp-fault", "true", 5, "false"),
                                        ("x-limit-max", "true", 6, "false")):
        if reaction(hal, name, value, column, opencnc, source_dir, work) != 0:
            return 1
        hal.sets(name, reset)
        time.sleep(0.3)
    return 0


def kill_controller(opencnc, source_dir, hal, work):
    before = len(hal.samples())
    run = controller(opencnc, source_dir, "long_move.ngc", work)
    if not wait_for_motion(hal, before):
        return fail("the program never moved X")
    time.sleep(1.0)
    run.send_signal(signal.SIGKILL)
    run.wait()
    time.sleep(1.0)
    rows = hal.samples()
    xs = [r[0] for r in rows]
    v = [(b - a) / PERIOD_S for a, b in zip(xs, xs[1:])]
    peak = max(v)
    top = v.index(peak)
    stopped = next((i for i in range(top, len(v)) if abs(v[i]) < 1e-9 and all(abs(w) < 1e-9 for w in v[i:i + 50])),
                   None)
    if stopped is None:
        return fail("the axis did not come to rest after the controller was killed")
    decel = max(abs(b - a) / PERIOD_S for a, b in zip(v[top:stopped], v[top + 1:stopped + 1]))
    enabled_at_end = rows[-1][3]
    print(f"peak {peak:.1f} mm/s, at rest {stopped - top} periods later, largest deceleration {decel:.0f} mm/s^2, "
          f"drive enable at the end {enabled_at_end}")
    if decel > 1000 * 1.05:
        return fail("the stop exceeded the axis's acceleration (1000 mm/s^2)")
    if enabled_at_end:
        return fail("the drive is still enabled with no controller")
    # The tick kept its servo (the same set-up) and drops what the dead controller staged.
    again = controller(opencnc, source_dir, "short_move.ngc", work)
    code = again.wait(timeout=60)
    if code != 0:
        print((work / "run.out").read_text())
        return fail(f"a new controller attached after the kill exited {code}")
    print("a new controller attached to the same tick and ran short_move.ngc to the end")
    return 0


def fail(why):
    print("FAIL:", why)
    return 1


def main():
    if len(sys.argv) >= 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    if len(sys.argv) != 5 or sys.argv[1] not in ("same-as-virtual", "safety-pins", "kill-controller"):
        print(__doc__, file=sys.stderr)
        return 2
    test, opencnc, component, source_dir = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3]), Path(sys.argv[4])
    if shutil.which("halrun") is None or shutil.which("halsampler") is None:
        print("SKIPPED: halrun is not installed (scripts/setup.sh --tests installs linuxcnc-uspace)")
        return SKIP
    if not component.is_file():
        print(f"SKIPPED: {component} was not built (hal.h missing: scripts/setup.sh --tests)")
        return SKIP
    installed = MODULES / "opencnc_rt.so"
    if installed.resolve() != component.resolve():
        try:  # where rtapi_app finds it (loadrt takes no path): this build's, as a link
            if installed.is_symlink() or installed.exists():
                installed.unlink()
            installed.symlink_to(component.resolve())
        except OSError as e:
            print(f"SKIPPED: cannot install {component} as {installed} ({e}); see docs/hal.md, Install")
            return SKIP
    with tempfile.TemporaryDirectory(prefix="opencnc-hal-") as d:
        work = Path(d)
        hal = Hal(source_dir, work)
        try:
            return {"same-as-virtual": same_as_virtual, "safety-pins": safety_pins,
                    "kill-controller": kill_controller}[test](opencnc, source_dir, hal, work)
        finally:
            hal.close()


if __name__ == "__main__":
    sys.exit(main())
