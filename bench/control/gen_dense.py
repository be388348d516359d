#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Writes a long, dense program for the streaming benchmark: N short feed moves (a zig-zag of
# 0.05 mm steps along X, creeping up Y) at F6000 under G64 P0.01, then M2. About 22 bytes a line;
# 10 million lines take 5000 s of machining.
#   gen_dense.py OUTPUT [N]     (N defaults to 1000000)
import argparse
import os
import sys


def main():
    ap = argparse.ArgumentParser(description="Write a long dense G-code program (zig-zag of short moves).")
    ap.add_argument("output", help="the program file to write (must not exist)")
    ap.add_argument("n", nargs="?", type=int, default=1_000_000, help="number of moves (default 1000000)")
    a = ap.parse_args()
    if a.n < 1:
        ap.error("n must be at least 1")
    if os.path.exists(a.output):
        ap.error(f"{a.output} exists: choose a new file")
    with open(a.output, "x") as f:
        f.write("G21 G90 G17 G64 P0.01 F6000\n")
        for i in range(a.n):
            f.write("G1 X%.3f Y%.4f\n" % ((i % 2) * 0.05, i * 0.0001))
        f.write("M2\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
