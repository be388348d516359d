#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Compares `opencnc canon` with LinuxCNC's `rs274 -g` on G-code programs: whole output, the
# motion subset (numbers within 1e-4), exit status and, for rejected programs, the problem.
"""usage: diff_rs274.py [--opencnc PATH] [--tools TBL] [--manifest] [--show N] FILE...

--manifest   use gcode-corpus/MANIFEST.tsv to decide per file whether -t tools.tbl is needed
--show N     print the first N differing lines of each mismatch
Exit status: 0 if every file matches in the motion subset and status, else 1.
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MOTION = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED", "DWELL", "SET_FEED_RATE", "SELECT_PLANE",
          "CHANGE_TOOL(", "START_SPINDLE_CLOCKWISE", "START_SPINDLE_COUNTERCLOCKWISE", "STOP_SPINDLE_TURNING",
          "SET_SPINDLE_SPEED", "PROGRAM_END", "PROGRAM_STOP")
NUM = re.compile(r"-?\d+\.\d+|-?\d+")


def load_error_map():
    """rs274 message pattern -> opencnc problem code, from tests/conformance/error-codes.tsv (the
    conformance suite's table: whole-message patterns, first match wins)."""
    table = []
    with open(os.path.join(HERE, "..", "conformance", "error-codes.tsv")) as f:
        for line in f:
            if not line.strip() or line.startswith("#"):
                continue
            pattern, code, _ = line.rstrip("\n").split("\t", 2)
            table.append((re.compile(pattern), code))
    return table


def call_text(line):
    """Drops the '   12 N..... ' prefix (sequence number and N label)."""
    return line[13:] if len(line) > 13 else line


def motion_calls(lines):
    out = []
    for ln in lines:
        text = call_text(ln)
        if text.startswith(MOTION):
            out.append(text)
    return out


def same_call(a, b, tol=1e-4):
    na, nb = NUM.findall(a), NUM.findall(b)
    if NUM.sub("#", a) != NUM.sub("#", b) or len(na) != len(nb):
        return False
    return all(abs(float(x) - float(y)) <= tol for x, y in zip(na, nb))


def run(cmd, cwd, env=None):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, errors="replace", timeout=600, env=env)
    return p.returncode, p.stdout.splitlines(), p.stderr


def run_rs274(cmd, cwd):
    """rs274 keeps its tool table in $HOME/.tool.mmap and truncates it on start: a private HOME
    keeps it apart from other runs at the same time."""
    with tempfile.TemporaryDirectory() as home:
        return run(cmd, cwd, dict(os.environ, HOME=home))


def main():
    ap = argparse.ArgumentParser(usage=__doc__)
    ap.add_argument("files", nargs="+")
    ap.add_argument("--opencnc", default=os.path.join(HERE, "..", "..", "build", "opencnc"))
    ap.add_argument("--tools")
    ap.add_argument("--manifest", action="store_true")
    ap.add_argument("--show", type=int, default=0)
    args = ap.parse_args()
    errors = load_error_map()
    manifest = {}
    if args.manifest:
        corpus = os.path.join(HERE, "..", "..", "..", "shared", "gcode-corpus")
        with open(os.path.join(corpus, "MANIFEST.tsv")) as f:
            for row in csv.DictReader(f, delimiter="\t"):
                manifest[row["file"]] = row["rs274 result"]
    opencnc = os.path.abspath(args.opencnc)
    failures = 0
    for path in args.files:
        path = os.path.abspath(path)
        cwd, name = os.path.dirname(path), os.path.basename(path)
        tools = args.tools
        if args.manifest and manifest.get(name, "") != "ok" and os.path.exists(os.path.join(cwd, "tools.tbl")):
            tools = os.path.join(cwd, "tools.tbl")
        topt = ["-t", os.path.abspath(tools)] if tools else []
        rc1, out1, err1 = run_rs274(["rs274"] + topt + ["-g", path], cwd)
        rc2, out2, err2 = run([opencnc, "canon", path] + topt, cwd)
        full = out1 == out2
        m1, m2 = motion_calls(out1), motion_calls(out2)
        motion = len(m1) == len(m2) and all(same_call(a, b) for a, b in zip(m1, m2))
        status = (rc1 == 0) == (rc2 == 0)
        problem = ""
        if rc1 != 0:
            msg = [ln for ln in err1.splitlines() if ln != "executing"]
            msg = msg[0] if msg else ""
            want = next((code for rx, code in errors if rx.fullmatch(msg)), "?")
            errs = "\n".join(ln for ln in err2.splitlines() if ": error: " in ln)
            got = re.findall(r"\[([a-z]+\.[a-z0-9.-]+)\]", errs)
            got = got[0] if got else "-"
            problem = f"  rs274: {msg!r} -> {want}; opencnc: {got}"
            status = status and want == got
        ok = motion and status
        failures += 0 if ok else 1
        verdict = "OK  " if ok else "DIFF"
        print(f"{verdict} full={'yes' if full else 'no ':3} motion={'yes' if motion else 'no ':3} "
              f"rc={rc1}/{rc2} {name}{problem}")
        if args.show and not full:
            shown = 0
            for i in range(max(len(out1), len(out2))):
                a = out1[i] if i < len(out1) else "<none>"
                b = out2[i] if i < len(out2) else "<none>"
                if a != b:
                    print(f"    rs274  : {a}\n    opencnc: {b}")
                    shown += 1
                    if shown >= args.show:
                        break
            if err2.strip():
                print("    stderr: " + err2.strip().splitlines()[0])
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
