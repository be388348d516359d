#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Writes a flame-cutting nest whose scan makes about N feed segments from a few dozen lines: a
# part (a wavy outline of 199 kerf-compensated lines and a round hole) called in two nested
# loops, so that `opencnc nearest` measures the path index built from the interpreter's scan of
# a large program (docs/performance.md, "Flame retrace").
# usage: gen_nest.py N OUT.ngc
import argparse
import math

ap = argparse.ArgumentParser(description="Writes a nest of parts called in loops whose scan makes about N feed "
                             "segments (200 per part), for configs/flame-cutter.toml.")
ap.add_argument("n", type=int, help="feed segments, about (200 per part)")
ap.add_argument("out", help="the program to write")
args = ap.parse_args()
if args.n < 200:
    ap.error("N must be 200 or more")
parts = args.n // 200
cols = max(1, math.ceil(math.sqrt(parts * 2)))
rows = math.ceil(parts / cols)
cell = 3000.0 / cols
text = f"""(a nest of {parts} parts, {cols} x {rows}, cell {cell:.3f} mm: about {parts * 200} feed segments)
G21 G90 G17 G40 G64 P0.1
F600
o<part> sub
  (#1 #2 centre, #3 radius)
  #<k> = 0
  G0 X[#1 + #3 * 1.3] Y#2
  G41 D1 G1 X[#1 + #3] Y#2
  o101 while [#<k> LT 197]
    #<k> = [#<k> + 1]
    #<a> = [#<k> * 360 / 198]
    #<r> = [#3 * [1 + 0.05 * SIN[7 * #<a>]]]
    G1 X[#1 + #<r> * COS[#<a>]] Y[#2 + #<r> * SIN[#<a>]]
  o101 endwhile
  G1 X[#1 + #3] Y#2
  G40 G0 X#1 Y#2
  G3 X#1 Y#2 I[#3 / 4] J0
o<part> endsub
#<row> = 0
o1 while [#<row> LT {rows}]
  #<col> = 0
  o2 while [#<col> LT {cols} AND [#<row> * {cols} + #<col>] LT {parts}]
    o<part> call [[#<col> + 0.5] * {cell:.6f}] [[#<row> + 0.5] * {cell:.6f}] [{0.4 * cell:.6f}]
    #<col> = [#<col> + 1]
  o2 endwhile
  #<row> = [#<row> + 1]
o1 endwhile
M2
"""
with open(args.out, "w") as f:
    f.write(text)
