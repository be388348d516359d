#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Differential test of the lathe cycles against LinuxCNC's rs274: seeded random profiles
# (lines, R arcs, fillets, chamfers, pockets, all four quadrants) through G70/G71/G72 and their
# .1/.2 variants; compares the motion calls (numbers within 1e-4) and which programs fail.
# With --comp: G70 only, under cutter compensation (G41/G42 from a tool table of lathe tools,
# G41.1/G42.1 with D and L), entered by the cycle's own rapid or by a move before it.
"""usage: lathe_vs_rs274.py --opencnc PATH [--comp] [--seed N] [--count N] [--keep DIR] [--verbose]

Exit status 0 when every program agrees. Disagreeing programs are written to --keep DIR.
"""
import argparse
import os
import random
import re
import subprocess
import sys
import tempfile

NUM = re.compile(r"-?\d+\.\d+|-?\d+")
MOTION = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED")


def fmt(v):
    return f"{v:.4f}"


def profile(rng):
    """A contour from near the axis outwards, towards -Z, in the first quadrant."""
    n = rng.randint(2, 7)
    z = 0.0
    x = rng.uniform(0.5, 4.0)
    pts = [(x, z)]
    pocket = rng.random() < 0.4
    flat = False
    for _ in range(n):
        z -= rng.uniform(0.5, 6.0)
        if pocket and rng.random() < 0.3:
            x = max(0.5, x - rng.uniform(0.3, 2.0))
        elif flat or rng.random() < 0.6:   # no two flat lines in a row: they would be collinear
            x += rng.uniform(0.2, 3.0)
        flat = pts[-1][0] == x
        pts.append((x, z))
    lines = [f"G1 X{fmt(pts[0][0])} Z{fmt(pts[0][1])}"]
    for (x0, z0), (x1, z1) in zip(pts, pts[1:]):
        chord = ((x1 - x0) ** 2 + (z1 - z0) ** 2) ** 0.5
        kind = rng.random()
        extra = ""
        r = rng.random()
        if r < 0.15:
            extra = f" A{fmt(rng.uniform(0.1, 0.6))}"
        elif r < 0.25:
            extra = f" C{fmt(rng.uniform(0.1, 0.6))}"
        if kind < 0.3 and chord > 0.2:
            g = rng.choice(["G2", "G3"])
            lines.append(f"{g} X{fmt(x1)} Z{fmt(z1)} R{fmt(chord * rng.uniform(0.51, 2.0))}{extra}")
        else:
            lines.append(f"G1 X{fmt(x1)} Z{fmt(z1)}{extra}")
    top = max(p[0] for p in pts)
    return lines, top, pts[-1][1]


def transform(lines, mirror_x, mirror_z):
    out = []
    for ln in lines:
        def sub(m):
            letter, v = m.group(1), float(m.group(2))
            if (letter == "X" and mirror_x) or (letter == "Z" and mirror_z):
                v = -v
            return f"{letter}{fmt(v)}"
        t = re.sub(r"([XZ])(-?\d+\.\d+)", sub, ln)
        if mirror_x != mirror_z:
            t = t.replace("G2 ", "G#").replace("G3 ", "G2 ").replace("G#", "G3 ")
        out.append(t)
    return out


def transpose(lines):
    """A turning contour as a facing one: X = -Z, Z = -X (arcs keep their sense: two mirrors)."""
    out = []
    for ln in lines:
        x = float(re.search(r"X(-?\d+\.\d+)", ln).group(1))
        z = float(re.search(r"Z(-?\d+\.\d+)", ln).group(1))
        t = re.sub(r"X-?\d+\.\d+", "X@", ln)
        t = re.sub(r"Z-?\d+\.\d+", f"Z{fmt(-x)}", t)
        out.append(t.replace("X@", f"X{fmt(-z)}"))
    return out


def program(rng):
    lines, top, zend = profile(rng)
    cycle = rng.choice(["G71", "G71.1", "G71.2", "G72", "G72.1", "G72.2", "G70"])
    facing = cycle.startswith("G72") or (cycle == "G70" and rng.random() < 0.5)
    mirror_x, mirror_z = rng.random() < 0.3, rng.random() < 0.3
    if facing:
        lines = transpose(lines)
        top, zend = -zend, -top   # the start point must clear the transposed contour
    lines = transform(lines, mirror_x, mirror_z)
    sx = (top + rng.uniform(0.5, 3.0)) * (-1 if mirror_x else 1)
    sz = rng.uniform(0.5, 3.0) * (-1 if mirror_z else 1)
    if facing:
        sx, sz = (top + rng.uniform(0.5, 3.0)) * (-1 if mirror_x else 1), rng.uniform(0.5, 3.0) * (-1 if mirror_z else 1)
    words = f"X{fmt(sx)} Z{fmt(sz)}"
    if cycle == "G70":
        words += f" D{fmt(rng.uniform(0, 1))} E{fmt(rng.uniform(0, 0.3))} P{rng.randint(1, 3)}"
    else:
        words += f" D{fmt(rng.choice([0, rng.uniform(0, 0.8)]))} I{fmt(rng.uniform(0.2, 1.5))} R{fmt(rng.uniform(0, 0.6))}"
    body = "\n".join("  " + ln for ln in lines)
    return f"G21 G18 G90 G8 F100\nG0 X{fmt(sx)} Z{fmt(sz)}\no100 sub\n{body}\no100 endsub\n{cycle} Q100 {words}\nG0 X{fmt(sx)} Z{fmt(sz)}\nM2\n"


# Lathe tools for --comp: nose diameter D (in inches, rs274's machine units without an ini
# file; the programs are metric) and orientation Q.
TOOLS = """T1 P1 D0.016 Q2
T2 P2 D0.008 Q3
T3 P3 D0.031 Q9
T4 P4 D0.012 Q6
T5 P5 D0.012
T6 P6 D0.02 Q8
"""


def program_comp(rng):
    """G70 under compensation: radius and orientation at random, mostly on the side away from
    the material (the other side often gouges, and both interpreters must say so)."""
    lines, top, zend = profile(rng)
    facing = rng.random() < 0.5
    mirror_x, mirror_z = rng.random() < 0.3, rng.random() < 0.3
    if facing:
        lines = transpose(lines)
        top, zend = -zend, -top
    lines = transform(lines, mirror_x, mirror_z)
    sx = (top + rng.uniform(0.5, 3.0)) * (-1 if mirror_x else 1)
    sz = rng.uniform(0.5, 3.0) * (-1 if mirror_z else 1)
    # The tool belongs on the start point's side of the contour (its first to last point), in
    # the (Z, X) plane of G18: left is G41.
    lx = float(re.search(r"X(-?\d+\.\d+)", lines[-1]).group(1))
    lz = float(re.search(r"Z(-?\d+\.\d+)", lines[-1]).group(1))
    fx = float(re.search(r"X(-?\d+\.\d+)", lines[0]).group(1))
    fz = float(re.search(r"Z(-?\d+\.\d+)", lines[0]).group(1))
    outside = "G41" if (lz - fz) * (sx - fx) - (lx - fx) * (sz - fz) > 0 else "G42"
    side = outside if rng.random() < 0.8 else ("G41" if outside == "G42" else "G42")
    if rng.random() < 0.5:
        comp = f"{side} D{rng.randint(1, 6)}"
    else:
        comp = f"{side}.1 D{fmt(rng.uniform(0.05, 0.8))}"
        if rng.random() < 0.8:
            comp += f" L{rng.randint(0, 9)}"
    # Where the tool waits: where a G71 or G72 over the same profile would have left it (level
    # with the start point, beside the contour's end), or anywhere near the start point.
    wx, wz = rng.choice([(sx, lz), (lx, sz), (sx + rng.choice([-1, 1]) * rng.uniform(1.0, 4.0),
                                                sz + rng.choice([-1, 1]) * rng.uniform(1.0, 4.0))])
    entry = ""
    if rng.random() < 0.4:   # compensation entered before the cycle: its rapid is a corner
        ex, ez = wx + rng.uniform(-2, 2), wz + rng.uniform(1.5, 4)
        entry = f"G{rng.choice([0, 1])} X{fmt(ex)} Z{fmt(ez)}\n"
    words = f"X{fmt(sx)} Z{fmt(sz)} D{fmt(rng.uniform(0, 1))} E{fmt(rng.uniform(0, 0.3))} P{rng.randint(1, 3)}"
    body = "\n".join("  " + ln for ln in lines)
    after = rng.choice(["G40\nG0 X{0} Z{1}\n", "G0 X{0} Z{1}\nG40\n", ""]).format(fmt(wx), fmt(wz + 1))
    diameter = "G7" if rng.random() < 0.2 else "G8"
    return (f"G21 G18 G90 {diameter} F100\nT{rng.randint(1, 6)} M6\nG0 X{fmt(wx)} Z{fmt(wz)}\no100 sub\n{body}\n"
            f"o100 endsub\n{comp}\n{entry}G70 Q100 {words}\n{after}M2\n")


def run(cmd, cwd):
    """(status, stdout lines, stderr); status None when the program did not finish in 10 s."""
    try:
        p = subprocess.run(["stdbuf", "-oL"] + cmd, cwd=cwd, capture_output=True, text=True, errors="replace",
                           timeout=10, env=dict(os.environ, HOME=cwd))
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace").splitlines()
        # rs274 sometimes hangs after it has printed the whole program: that run is complete.
        if any("PROGRAM_END()" in ln for ln in out):
            return 0, out, ""
        return None, out, ""
    return p.returncode, p.stdout.splitlines(), p.stderr


def motion(lines):
    return [ln[13:] for ln in lines if ln[13:].startswith(MOTION)]


def same(a, b):
    na, nb = NUM.findall(a), NUM.findall(b)
    if NUM.sub("#", a) != NUM.sub("#", b) or len(na) != len(nb):
        return False
    return all(abs(float(x) - float(y)) <= 1e-4 for x, y in zip(na, nb))


HERE = os.path.dirname(os.path.abspath(__file__))


def error_map():
    rows = []
    with open(os.path.join(HERE, "..", "conformance", "error-codes.tsv")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            pattern, code = line.rstrip("\n").split("\t")[:2]
            rows.append((re.compile(pattern), code))
    return rows


ERRORS = error_map()


def rs274_error(lines):
    """The first line of rs274's error message, or None (Oops lines are its debug output)."""
    for ln in lines:
        if ln.startswith(" ") or not ln.strip() or ln == "executing" or ln.startswith("Oops"):
            continue
        return ln
    return None


def expected_code(message):
    for pattern, code in ERRORS:
        if pattern.match(message):
            return code
    return "?"


def compare(opencnc, text, work, comp=False):
    path = os.path.join(work, "p.ngc")
    with open(path, "w") as f:
        f.write(text)
    tools = os.path.join(work, "tools.tbl")
    with open(tools, "w") as f:
        f.write(TOOLS)
    rc1, out1, err1 = run(["rs274", "-t", tools, "-g", "p.ngc"], work)
    rc2, out2, err2 = run([opencnc, "canon", "p.ngc", "--tool-table", tools], work)
    if rc1 is None:   # rs274 loops for ever on some profiles; opencnc must stop with an error
        return rc2 not in (0, None), "both failed: rs274 hangs, opencnc " + err2.strip()[-60:]
    if rc1 < 0:   # rs274 crashes (undefined behaviour in its offsetting); opencnc must stop with an error
        return rc2 not in (0, None), "both failed: rs274 crashes, opencnc " + err2.strip()[-60:]
    message = rs274_error(out1 + err1.splitlines())
    failed1, failed2 = message is not None, rc2 != 0
    m1, m2 = motion(out1), motion(out2)
    if failed1 != failed2:
        return False, f"failure differs: rs274 {message} / opencnc {err2.strip()[:300]}"
    if failed1:
        code = expected_code(message)
        # What was printed before the error must agree too (compensation holds moves back, and
        # both must hold back the same ones).
        if comp and (len(m1) != len(m2) or not all(same(a, b) for a, b in zip(m1, m2))):
            return False, f"motions before the error differ ({len(m1)} vs {len(m2)}): {message}"
        if (code.startswith("gcode.lathe") or code.startswith("gcode.comp")) and f"[{code}]" not in err2:
            return False, f"rs274 '{message}' ({code}) / opencnc {err2.strip()[:300]}"
        return True, "both failed: " + code
    if len(m1) != len(m2):
        return False, f"{len(m1)} vs {len(m2)} motions"
    for k, (a, b) in enumerate(zip(m1, m2)):
        if not same(a, b):
            return False, f"motion {k}: {a} | {b}"
    return True, "same"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--opencnc", required=True)
    ap.add_argument("--comp", action="store_true", help="G70 under cutter compensation")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--keep")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    bad = 0
    both_failed = 0
    reasons = {}
    with tempfile.TemporaryDirectory() as work:
        for i in range(args.count):
            text = program_comp(rng) if args.comp else program(rng)
            ok, why = compare(os.path.abspath(args.opencnc), text, work, args.comp)
            if why.startswith("both failed"):
                both_failed += 1
                reasons[why] = reasons.get(why, 0) + 1
            if not ok:
                bad += 1
                print(f"#{i}: {why}")
                if args.keep:
                    os.makedirs(args.keep, exist_ok=True)
                    with open(os.path.join(args.keep, f"case{i}.ngc"), "w") as f:
                        f.write(text)
            elif args.verbose:
                print(f"#{i}: {why}")
    print(f"{args.count - bad}/{args.count} agree ({both_failed} rejected by both: {reasons})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
