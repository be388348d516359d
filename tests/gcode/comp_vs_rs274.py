#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Differential test of cutter compensation: seeded random compensated programs through
# `opencnc canon` and LinuxCNC's `rs274 -g`; the whole outputs must agree (numbers within
# 1e-4) and a program rs274 rejects must be rejected with the code error-codes.tsv maps to.
"""usage: comp_vs_rs274.py [--opencnc PATH] [--seed S] [--count N] [--keep DIR] [--show]

Each program: a random contour of lines and arcs (I/J/K or R, G2/G3, sometimes several turns)
in G17 or G18, entered with G41/G42/G41.1/G42.1 from a tool table or a D diameter, with Z (or Y)
moves, feed changes, comments, G91 stretches, G20/G21 switches and M1 stops in between, left
with G40. Exit status 1 if any program differs; failing programs are kept in --keep.
"""
import argparse
import math
import os
import random
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
NUM = re.compile(r"-?\d+\.\d+|-?\d+")
TOOLS = """T1 P1 Z1 D0.25
T2 P2 Z1 D0.125
T3 P3 Z1 D-0.1
T4 P4 Z1 D0.5
T7 P7 X0.05 Z0.1 D0.04 Q2
T8 P8 Z0.1 D0.06 Q3
"""


def error_map():
    """rs274 message -> the code opencnc reports for the same problem (the conformance suite's table)."""
    rows = []
    with open(os.path.join(ROOT, "tests", "conformance", "error-codes.tsv")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            pattern, code = line.rstrip("\n").split("\t")[:2]
            rows.append((re.compile(pattern), code))
    return rows


def fmt(v):
    return ("%.4f" % v).rstrip("0").rstrip(".") or "0"


class Gen:
    """Writes one random program; coordinates in the comp plane's (first, second) letters."""

    def __init__(self, rnd):
        self.r = rnd
        self.lines = []
        self.xz = rnd.random() < 0.25
        self.a, self.b = ("Z", "X") if self.xz else ("X", "Y")
        self.ia, self.ib = ("K", "I") if self.xz else ("I", "J")
        self.n = "Y" if self.xz else "Z"
        self.inch = False

    def emit(self, s):
        self.lines.append(s)

    def point(self, scale=30):
        if self.inch:
            scale /= 25.4
        return self.r.uniform(-scale, scale), self.r.uniform(-scale, scale)

    def ride(self):
        """Words of axes riding along: the normal axis (a helix) or A."""
        k = self.r.random()
        if k < 0.05:
            return " %s%s" % (self.n, fmt(self.r.uniform(-3, 3)))
        if k < 0.1:
            return " A%s" % fmt(self.r.uniform(0, 90))
        return ""

    def extras(self):
        r = self.r
        k = r.random()
        if k < 0.05:
            self.emit("F%d" % r.randint(50, 500))
        elif k < 0.08:
            self.emit("(note %d)" % r.randint(0, 99))
        elif k < 0.10:
            self.emit("G1 %s%s" % (self.n, fmt(r.uniform(-3, 3))))
        elif k < 0.11:
            self.emit("M1")
        elif k < 0.12:
            self.emit("G4 P0.5")
        elif k < 0.13 and not self.xz:
            self.emit("G0 Z%s" % fmt(r.uniform(0, 3)))
        elif k < 0.14:
            # a change of units scales what compensation holds (and the tool radius)
            self.inch = not self.inch
            self.emit("G20" if self.inch else "G21")

    def arc(self, cur, end):
        """A G2/G3 from cur to end, centre on the bisector (I/J/K or R)."""
        r = self.r
        mx, my = (cur[0] + end[0]) / 2, (cur[1] + end[1]) / 2
        dx, dy = end[0] - cur[0], end[1] - cur[1]
        d = math.hypot(dx, dy)
        if d < 1e-3:
            return None
        t = r.uniform(-2, 2)
        cx, cy = mx - dy / d * t * d, my + dx / d * t * d
        g = r.choice(("G2", "G3"))
        if r.random() < 0.3:
            rad = math.hypot(cx - cur[0], cy - cur[1])
            rad = max(rad, d / 2 + 0.01)
            sign = "-" if r.random() < 0.3 else ""
            return "%s %s%s %s%s R%s%s%s" % (g, self.a, fmt(end[0]), self.b, fmt(end[1]), sign, fmt(rad), self.ride())
        # snap the end onto the circle so the radius check passes
        rad = math.hypot(cx - cur[0], cy - cur[1])
        ang = math.atan2(end[1] - cy, end[0] - cx)
        ex, ey = cx + rad * math.cos(ang), cy + rad * math.sin(ang)
        p = " P2" if r.random() < 0.05 else ""
        if r.random() < 0.05:   # a full circle
            ex, ey = cur
        return "%s %s%s %s%s %s%s %s%s%s%s" % (g, self.a, fmt(ex), self.b, fmt(ey), self.ia, fmt(cx - cur[0]),
                                                 self.ib, fmt(cy - cur[1]), p, self.ride())

    def program(self):
        r = self.r
        self.emit("G18" if self.xz else "G17")
        self.emit("G21 G90 F200")
        tool = r.choice((1, 2, 3, 4, 7, 8) if self.xz else (1, 2, 3, 4))
        self.emit("T%d M6" % tool)
        pos = self.point()
        self.emit("G0 %s%s %s%s" % (self.a, fmt(pos[0]), self.b, fmt(pos[1])))
        for _ in range(r.randint(1, 3)):
            pos = self.contour(pos)
        self.emit("M2")
        return "\n".join(self.lines) + "\n"

    def contour(self, start):
        r = self.r
        side = r.choice(("G41", "G42"))
        k = r.random()
        if k < 0.3:
            on = "%s.1 D%s" % (side, fmt(r.uniform(-3, 6)))
            if self.xz and r.random() < 0.5:
                on += " L%d" % r.randint(0, 9)
        elif k < 0.5:
            on = "%s D%d" % (side, r.choice((1, 2, 3, 4)))
        else:
            on = side
        cur = self.point()
        entry_arc = r.random() < 0.15
        if entry_arc:
            self.emit(on)
            a = self.arc(start, cur)
            self.emit(a or "G1 %s%s %s%s" % (self.a, fmt(cur[0]), self.b, fmt(cur[1])))
        else:
            self.emit("%s G1 %s%s %s%s" % (on, self.a, fmt(cur[0]), self.b, fmt(cur[1])))
        first = cur
        incremental = False
        for i in range(r.randint(1, 10)):
            self.extras()
            nxt = first if i == 9 else self.point()
            if r.random() < 0.1 and not incremental:
                self.emit("G91")
                incremental = True
            elif incremental and r.random() < 0.5:
                self.emit("G90")
                incremental = False
            if r.random() < 0.5 and not incremental:
                a = self.arc(cur, nxt)
                if a:
                    self.emit(a)
                    # arcs written with I/J end where the snapped end is; track it roughly
                    m = re.search(r"%s(-?[\d.]+) %s(-?[\d.]+)" % (self.a, self.b), a)
                    cur = (float(m.group(1)), float(m.group(2)))
                    continue
            if incremental:
                self.emit("G1 %s%s %s%s%s" % (self.a, fmt(nxt[0] - cur[0]), self.b, fmt(nxt[1] - cur[1]), self.ride()))
            elif r.random() < 0.03:
                self.emit("G93 G1 %s%s %s%s F2" % (self.a, fmt(nxt[0]), self.b, fmt(nxt[1])))
                self.emit("G94 F200")
            else:
                self.emit("G%d %s%s %s%s%s" % (r.choice((0, 1, 1, 1)), self.a, fmt(nxt[0]), self.b, fmt(nxt[1]),
                                               self.ride()))
            cur = nxt
        if incremental:
            self.emit("G90")
        self.lines.append("F200")
        if r.random() < 0.8:
            cur = self.point()
            self.emit("G40 G1 %s%s %s%s" % (self.a, fmt(cur[0]), self.b, fmt(cur[1])))
        else:
            self.emit("G40")
        return cur


def listing(lines):
    return [ln[13:] for ln in lines if len(ln) > 13 and ln[:6].strip().isdigit()]


def same(a, b):
    na, nb = NUM.findall(a), NUM.findall(b)
    return NUM.sub("#", a) == NUM.sub("#", b) and len(na) == len(nb) and all(
        abs(float(x) - float(y)) <= 1e-4 for x, y in zip(na, nb))


def compare(opencnc, path, tbl, errors, home):
    rs = subprocess.run(["rs274", "-t", tbl, "-g", path], capture_output=True, text=True,
                        env=dict(os.environ, HOME=home))
    oc = subprocess.run([opencnc, "canon", path, "-t", tbl], capture_output=True, text=True)
    rl, ol = listing(rs.stdout.splitlines()), listing(oc.stdout.splitlines())
    return rs.returncode == 0, differ(rs, oc, rl, ol, errors)


def differ(rs, oc, rl, ol, errors):
    if rs.returncode != 0:
        msg = [ln for ln in rs.stderr.splitlines() if ln and ln != "executing"][:1]
        want = [c for p, c in errors if msg and p.search(msg[0])]
        if oc.returncode == 0:
            return "rs274 rejects (%s), opencnc accepts" % (msg[0] if msg else "?")
        if not any(re.search(r"\[%s\]" % re.escape(c), oc.stderr) for c in want):
            return "rs274: %s (%s); opencnc: %s" % (msg[0] if msg else "?", want, oc.stderr.strip()[:200])
        rl = rl[:len(ol)]   # what both printed before the error
    elif oc.returncode != 0:
        return "opencnc rejects: " + oc.stderr.strip()[:200]
    if len(rl) != len(ol):
        return "%d calls vs rs274's %d" % (len(ol), len(rl))
    for i, (a, b) in enumerate(zip(ol, rl)):
        if not same(a, b):
            return "call %d: %s | rs274: %s" % (i + 1, a, b)
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--opencnc", default=os.path.join(ROOT, "build", "opencnc"))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--keep", default="/tmp/comp_vs_rs274")
    ap.add_argument("--show", action="store_true")
    a = ap.parse_args()
    errors = error_map()
    os.makedirs(a.keep, exist_ok=True)
    bad = accepted = 0
    with tempfile.TemporaryDirectory() as tmp:
        tbl = os.path.join(tmp, "tools.tbl")
        with open(tbl, "w") as f:
            f.write(TOOLS)
        home = os.path.join(tmp, "home")
        os.makedirs(home)
        for k in range(a.count):
            seed = a.seed * 100003 + k
            text = Gen(random.Random(seed)).program()
            path = os.path.join(tmp, "p%d.ngc" % seed)
            with open(path, "w") as f:
                f.write(text)
            ok, problem = compare(a.opencnc, path, tbl, errors, home)
            accepted += ok
            if problem:
                bad += 1
                keep = os.path.join(a.keep, "p%d.ngc" % seed)
                with open(keep, "w") as f:
                    f.write(text)
                print("%s: %s" % (keep, problem))
    print("%d programs (%d accepted by rs274), %d differ" % (a.count, accepted, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
