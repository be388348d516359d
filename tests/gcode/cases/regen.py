#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Regenerates the expected output (NAME.rs274) of every case from LinuxCNC's `rs274 -g`, the
# oracle; checks that rs274 fails exactly on the cases that expect an error, with the problem
# the case names (via ../rs274_errors.tsv).
"""usage: regen.py [CASE.ngc ...]   (default: every case in this directory)

Directives on ";" lines of a case (ignored by both interpreters):
  ; opencnc-test: tools                  run with -t tools.tbl
  ; opencnc-test: subroutine-path=DIR    sub files are searched in DIR
  ; opencnc-test: error=gcode.CODE       rs274 must reject the program with this problem
"""
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def directives(path):
    out = {}
    with open(path) as f:
        for line in f:
            m = re.match(r";\s*opencnc-test:\s*(.*)", line)
            if not m:
                continue
            for item in m.group(1).split():
                key, _, value = item.partition("=")
                out[key] = value or True
    return out


def error_map():
    table = []
    with open(os.path.join(HERE, "..", "rs274_errors.tsv")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                code, pattern = line.rstrip("\n").split("\t", 1)
                table.append((re.compile(pattern), code))
    return table


def run_rs274(args):
    # rs274 keeps its tool table in shared memory, which concurrent runs can disturb:
    # repeat until two runs agree.
    last = None
    for _ in range(8):
        p = subprocess.run(args, cwd=HERE, capture_output=True, text=True)
        now = (p.returncode, p.stdout, p.stderr)
        if now == last:
            return now
        last = now
    return last


def main():
    cases = sys.argv[1:] or sorted(f for f in os.listdir(HERE) if f.endswith(".ngc"))
    errors = error_map()
    bad = 0
    for case in cases:
        path = os.path.join(HERE, os.path.basename(case))
        d = directives(path)
        args = ["rs274"]
        if d.get("tools"):
            args += ["-t", "tools.tbl"]
        with tempfile.NamedTemporaryFile("w", suffix=".ini", delete=False) as ini:
            ini.write("[RS274NGC]\nSUBROUTINE_PATH = %s\n" % os.path.join(HERE, d.get("subroutine-path", ".")))
        args += ["-i", ini.name, "-g", os.path.basename(path)]
        rc, out, err = run_rs274(args)
        os.unlink(ini.name)
        message = next((ln for ln in err.splitlines() if ln.strip() and ln != "executing"), "")
        want = d.get("error")
        got = next((code for rx, code in errors if rx.search(message)), None) if rc != 0 else None
        if want != got:
            print(f"{case}: expects {want or 'success'}, rs274 gave {got or 'success'} ({message!r})")
            bad += 1
            continue
        with open(path[:-4] + ".rs274", "w") as f:
            f.write(out)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
