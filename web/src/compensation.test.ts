// SPDX-License-Identifier: GPL-3.0-or-later
// The compensation screen's logic: the set-compensation command from the admin's inputs (checked
// before anything is sent), the points' positions, and the plot.
import { describe, expect, it } from "vitest";
import { compensationCommand, nextRow, plotSvg, positionsOf, spacing, type CompensationAxis } from "./screens/compensation";

const x: CompensationAxis = {
  axis: "X",
  unit: "mm",
  backlash: 0.02,
  takeup_velocity: 2,
  takeup_acceleration: 40,
  table: { positions: [0, 50, 100], forward: [0, 0.003, 0.006], reverse: [0, 0.003, 0.006], one_table: true },
  comp_file: null,
  editable: true,
  max_points: 256,
};
const rows = (f: string[], r: string[]) => f.map((v, i) => ({ forward: v, reverse: r[i] }));
const y: CompensationAxis = {
  ...x,
  axis: "Y",
  table: { positions: [0, 40, 100], forward: [0, -0.002, -0.005], reverse: [0.01, 0.008, 0.005], one_table: false },
  comp_file: "y.comp",
  comp_file_type: 0,
};
const points = (p: string[]) => p.map((position) => ({ forward: "0", reverse: "0", position }));

describe("compensation", () => {
  it("sends both directions as numbers, and start and interval only when they changed", () => {
    expect(spacing(x)).toEqual({ start: 0, interval: 50 });
    expect(compensationCommand(x, { start: "0", interval: "50", rows: rows(["0", "0.004", "0.006"], ["0.001", "0.004", "0.007"]) })).toEqual({
      kind: "set-compensation",
      axis: "X",
      forward: [0, 0.004, 0.006],
      reverse: [0.001, 0.004, 0.007],
    });
    expect(compensationCommand(x, { start: "-10", interval: "100", rows: rows(["0", "0"], ["0", "0"]) })).toEqual({
      kind: "set-compensation",
      axis: "X",
      forward: [0, 0],
      reverse: [0, 0],
      start: -10,
      interval: 100,
    });
  });
  it("refuses empty fields, text, no points, too many points and a zero interval before sending", () => {
    expect(compensationCommand(x, { start: "0", interval: "50", rows: rows(["0", ""], ["0", "0"]) })).toBe("X point 2, moving +: a value is needed");
    expect(compensationCommand(x, { start: "0", interval: "50", rows: rows(["0"], ["a"]) })).toBe('X point 1, moving −: "a" is not a number');
    expect(compensationCommand(x, { start: "0", interval: "50", rows: [] })).toBe("X: a table has 1 to 256 points (this one 0)");
    const many = Array.from({ length: 257 }, () => ({ forward: "0", reverse: "0" }));
    expect(compensationCommand(x, { start: "0", interval: "50", rows: many })).toBe("X: a table has 1 to 256 points (this one 257)");
    expect(compensationCommand(x, { start: "0", interval: "0", rows: rows(["0"], ["0"]) })).toBe("X interval: must be greater than 0");
  });
  it("places the points at start + k·interval", () => {
    expect(positionsOf({ start: "10", interval: "25", rows: rows(["0", "0", "0"], ["0", "0", "0"]) })).toEqual([10, 35, 60]);
  });
  it("plots both directions in µm over the positions, with the ends labelled", () => {
    const svg = plotSvg([0, 50, 100], [0, 0.003, 0.006], [0.002, 0.004, 0.008], "mm", 200, 100);
    expect(svg.match(/<polyline/g)?.length).toBe(2);
    expect(svg.match(/<circle class="forward"/g)?.length).toBe(3);
    expect(svg).toContain(">8 µm<");
    expect(svg).toContain(">0 µm<");
    expect(svg).toContain(">100 mm<");
    // The forward line starts at the left end at 0 µm (the bottom of this plot) and ends at the right.
    expect(svg).toContain('points="48.0,76.0 ');
    expect(svg).toMatch(/190\.0,\d+\.\d"\/>/);
    expect(plotSvg([], [], [], "mm")).not.toContain("polyline");
  });
  it("a comp file's points: their own positions, sent only when they changed, and increasing", () => {
    expect(compensationCommand(y, { start: "", interval: "", rows: points(["0", "40", "100"]) })).toEqual({
      kind: "set-compensation",
      axis: "Y",
      forward: [0, 0, 0],
      reverse: [0, 0, 0],
    });
    expect(compensationCommand(y, { start: "", interval: "", rows: points(["0", "50", "100", "130"]) })).toEqual({
      kind: "set-compensation",
      axis: "Y",
      forward: [0, 0, 0, 0],
      reverse: [0, 0, 0, 0],
      positions: [0, 50, 100, 130],
    });
    expect(compensationCommand(y, { start: "", interval: "", rows: points(["0", "100", "100"]) })).toBe(
      "Y point 3, position: must be greater than point 2's (100)",
    );
    expect(compensationCommand(y, { start: "", interval: "", rows: points(["0", ""]) })).toBe("Y point 2, position: a value is needed");
    expect(positionsOf({ start: "", interval: "", rows: points(["0", "40", "100"]) })).toEqual([0, 40, 100]);
  });
  it("adds a comp file's point one interval beyond the last", () => {
    expect(nextRow(points(["0", "40", "100"]), true)).toEqual({ forward: "0", reverse: "0", position: "160" });
    expect(nextRow(points(["5"]), true).position).toBe("6");
    expect(nextRow(rows(["0.1"], ["0.2"]), false)).toEqual({ forward: "0.1", reverse: "0.2" });
  });
});
