#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Writes N tangent arcs of radius R alternating G3/G2, each sweeping SWEEP degrees, at F3000 under
# G64 P0.1: the small-arc case of docs/planner.md (same shape as analysis::small_arcs_program).
# usage: gen_small_arcs.py N SWEEP_DEG OUT.ngc [R]
import argparse
import math

ap = argparse.ArgumentParser(description="Writes N tangent arcs of radius R alternating G3/G2, each sweeping "
                             "SWEEP_DEG degrees, at F3000 under G64 P0.1.")
ap.add_argument("n", type=int, help="number of arcs")
ap.add_argument("sweep_deg", type=float, help="degrees each arc sweeps")
ap.add_argument("out", help="the program to write")
ap.add_argument("r", nargs="?", type=float, default=0.3, help="arc radius in mm (default 0.3)")
args = ap.parse_args()
if args.n < 1 or not (args.r > 0) or not math.isfinite(args.sweep_deg):
    ap.error("N must be 1 or more, R positive and SWEEP_DEG finite")
n, sweep_deg, out, r = args.n, args.sweep_deg, args.out, args.r
sweep = math.radians(sweep_deg)
lines = ["(%d alternating G3/G2 arcs, R%g, %g deg each, F3000, G64 P0.1)" % (n, r, sweep_deg),
         "G21 G17 G90 G94", "G64 P0.1", "G0 X0 Y0 Z0", "F3000"]
x = y = heading = 0.0
for i in range(n):
    turn = 1 if i % 2 == 0 else -1
    cx, cy = x - math.sin(heading) * turn * r, y + math.cos(heading) * turn * r
    a1 = math.atan2(y - cy, x - cx) + turn * sweep
    ex, ey = cx + r * math.cos(a1), cy + r * math.sin(a1)
    lines.append("%s X%.4f Y%.4f I%.4f J%.4f" % ("G3" if turn > 0 else "G2", ex, ey, cx - x, cy - y))
    x, y, heading = ex, ey, heading + turn * sweep
lines.append("M2")
open(out, "w").write("\n".join(lines) + "\n")
