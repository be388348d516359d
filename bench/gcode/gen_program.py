#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Writes the benchmark program: a feed rate, then N lines "G1 X.. Y.. Z.." (about 28 bytes
# each), then M2. Deterministic (seeded) so that every run measures the same file.
import random
import sys


def main():
    path = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    rng = random.Random(1)
    with open(path, "w") as f:
        f.write("G21 G90 G17 F1500\n")
        for _ in range(n):
            f.write("G1 X%.3f Y%.3f Z%.3f\n" % (rng.uniform(-500, 500), rng.uniform(-500, 500), rng.uniform(-50, 0)))
        f.write("M2\n")


if __name__ == "__main__":
    main()
