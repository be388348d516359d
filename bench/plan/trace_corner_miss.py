#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# trace_corner_miss.py — how far each programmed end point lies from a recorded path: the LinuxCNC
# harness's --trace CSV (cycle,t_s,x,y,z,...) or jerk_table --trace (time,line,x,y,z,v), against
# the end points of LinuxCNC's own `rs274 -g` listing of the program (docs/performance.md,
# "Jerk-limited motion": does a planner keep its G64 P?).
#
#   rs274 -g PROGRAM.ngc > PROGRAM.canon
#   bench/plan/trace_corner_miss.py PROGRAM.canon TRACE.csv [TOLERANCE_MM]
#
# The path is the polyline through the samples (1 ms apart: a chord of a blend of radius R at v
# lies within v²·dt²/(8R) of it, 0.5 µm at 64 mm/s and R = 1 mm). The end points are taken in
# order and each is searched for near where the last one was found, so a path that comes back
# near an earlier point is not mistaken for it.
import csv
import math
import re
import sys

MOVE = re.compile(r"(STRAIGHT_FEED|STRAIGHT_TRAVERSE|ARC_FEED)\(([^)]*)\)")


def end_points(listing):
    """The XYZ end point of every move of an rs274 -g listing (mm, as the program's units)."""
    points = []
    for line in listing:
        m = MOVE.search(line)
        if not m:
            continue
        args = [float(a) for a in m.group(2).split(",")]
        if m.group(1) == "ARC_FEED":  # first_end, second_end, axis centres, rotation, axis_end
            points.append((args[0], args[1], args[4]))  # XY plane (G17) only
        else:
            points.append(tuple(args[:3]))
    return points


def samples(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if rows and rows[0] and rows[0][0] == "cycle":  # the LinuxCNC harness
        head = rows[0]
        ix, iy, iz = head.index("x"), head.index("y"), head.index("z")
        return [(float(r[ix]), float(r[iy]), float(r[iz])) for r in rows[1:]]
    return [(float(r[2]), float(r[3]), float(r[4])) for r in rows]


def segment_distance(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    den = sum(x * x for x in ab)
    t = 0.0 if den == 0 else max(0.0, min(1.0, sum(ab[i] * ap[i] for i in range(3)) / den))
    return math.dist(p, [a[i] + t * ab[i] for i in range(3)])


def main():
    usage = "usage: trace_corner_miss.py PROGRAM.canon TRACE.csv [TOLERANCE_MM]"
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        print(usage)
        return 0
    if len(sys.argv) < 3:
        print(usage, file=sys.stderr)
        return 2
    with open(sys.argv[1]) as f:
        points = end_points(f)
    path = samples(sys.argv[2])
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    at, misses = 0, []
    for p in points:
        best, best_k = math.inf, at
        for k in range(max(0, at - 200), min(len(path) - 1, at + 5000)):
            d = segment_distance(p, path[k], path[k + 1])
            if d < best:
                best, best_k = d, k
        at = best_k
        misses.append(best)
    worst = max(misses) if misses else 0.0
    print(f"{len(points)} end points, largest distance to the path {worst:.4f} mm")
    if tol > 0:
        over = sum(1 for d in misses if d > tol * (1 + 1e-3))
        print(f"{over} farther than {tol:g} mm (+0.1 %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
