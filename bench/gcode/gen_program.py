#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Writes the benchmark program: a feed rate, then N lines "G1 X.. Y.. Z.." (about 28 bytes
# each), then M2. Deterministic (seeded) so that every run measures the same file.
import argparse
import random


def main():
    ap = argparse.ArgumentParser(description="Writes the benchmark program: a feed rate, N lines 'G1 X.. Y.. Z..' "
                                 "and M2 (seeded, so every run measures the same file).")
    ap.add_argument("path", help="the program to write (refused if it exists: no file is replaced)")
    ap.add_argument("lines", nargs="?", type=int, default=1_000_000, help="number of G1 lines (default 1000000)")
    args = ap.parse_args()
    if args.lines < 0:
        ap.error("lines must be 0 or more")
    path, n = args.path, args.lines
    rng = random.Random(1)
    try:
        f = open(path, "x")
    except OSError as e:
        ap.error(f"cannot create {path}: {e.strerror}")
    with f:
        f.write("G21 G90 G17 F1500\n")
        for _ in range(n):
            f.write("G1 X%.3f Y%.3f Z%.3f\n" % (rng.uniform(-500, 500), rng.uniform(-500, 500), rng.uniform(-50, 0)))
        f.write("M2\n")


if __name__ == "__main__":
    main()
