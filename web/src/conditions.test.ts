// SPDX-License-Identifier: GPL-3.0-or-later
// The machining-conditions screen's logic: each condition's cells, which one is in force, who may
// edit them, the admin's edit as a set-conditions command, an add and a delete.
import { describe, expect, it } from "vitest";
import {
  activeCondition,
  addConditionCommand,
  conditionCells,
  conditionCommand,
  conditionHeader,
  deleteQuestion,
  mayEdit,
  sequenceCells,
  sequenceHeader,
  sequenceQuery,
  type Condition,
  type ConditionField,
} from "./screens/conditions";
import type { Status } from "./types";

const roughing: Condition = {
  number: 1,
  on_time_us: 100,
  off_time_us: 50,
  peak_current_a: 12,
  voltage_v: 100,
  polarity: "+",
  servo_reference_v: 45,
  jump_height_mm: 0.4,
  jump_period_s: 0.25,
  jump_mode: "axis",
  orbit: "none",
  orbit_radius_mm: 0,
  orbit_step_mm: 0,
};

describe("machining conditions", () => {
  it("shows a condition's settings in the header's order", () => {
    expect(conditionCells(roughing)).toEqual(["E1", "100", "50", "12", "100", "+", "45", "0.4 / 0.25", "off"]);
    expect(conditionCells(roughing).length).toBe(conditionHeader.length);
  });
  it("names a jump back along the path, an orbit with its steps, and a jump that is off", () => {
    const finishing = { ...roughing, number: 3, jump_mode: "path", orbit: "square", orbit_radius_mm: 0.08, orbit_step_mm: 0.02 };
    expect(conditionCells(finishing).slice(7)).toEqual(["0.4 / 0.25 (path)", "square 0.08 mm by 0.02"]);
    expect(conditionCells({ ...roughing, jump_period_s: 0 })[7]).toBe("off");
  });
  it("takes the condition in force from the status' EDM values (0 without)", () => {
    expect(activeCondition({ edm: { condition: 2 } } as unknown as Status)).toBe(2);
    expect(activeCondition({} as Status)).toBe(0);
    expect(activeCondition(undefined)).toBe(0);
  });
});

const fields: ConditionField[] = [
  { key: "on_time_us", unit: "µs", what: "pulse on-time" },
  { key: "peak_current_a", unit: "A", what: "discharge current" },
  { key: "polarity", unit: "", what: "electrode + or −", choices: ["+", "-"] },
  { key: "orbit", unit: "", what: "the orbit's shape", choices: ["none", "circle", "square", "star"] },
];

describe("editing a machining condition", () => {
  it("is the admin's only: an operator's token sees the conditions read-only", () => {
    expect(mayEdit("admin")).toBe(true);
    expect(mayEdit("operator")).toBe(false);
    expect(mayEdit(undefined)).toBe(false);
  });
  it("sends only the fields that changed, numbers as numbers and choices as their words", () => {
    expect(conditionCommand(roughing, fields, { on_time_us: " 60 ", peak_current_a: "12", polarity: "-", orbit: "none" })).toEqual({
      kind: "set-conditions",
      condition: 1,
      values: { on_time_us: 60, polarity: "-" },
    });
    expect(conditionCommand(roughing, fields, { orbit: "circle" })).toEqual({ kind: "set-conditions", condition: 1, values: { orbit: "circle" } });
  });
  it("says in words what it will not send", () => {
    expect(conditionCommand(roughing, fields, { on_time_us: "long" })).toBe('E1 on_time_us: "long" is not a number');
    expect(conditionCommand(roughing, fields, { peak_current_a: " " })).toBe("E1 peak_current_a: a value is needed");
    expect(conditionCommand(roughing, fields, { polarity: "x" })).toBe("E1 polarity: one of + -");
    expect(conditionCommand(roughing, fields, {})).toBe("E1: nothing changed");
  });
});

describe("adding and deleting a machining condition", () => {
  const numbers = [1, 2, 3, 9];
  it("adds a new number as a copy of the chosen condition, or of the one below when none is chosen", () => {
    expect(addConditionCommand(numbers, " 4 ", 3)).toEqual({ kind: "add-condition", condition: 4, from: 3 });
    expect(addConditionCommand(numbers, "12", undefined)).toEqual({ kind: "add-condition", condition: 12 });
  });
  it("says in words what it will not send", () => {
    expect(addConditionCommand(numbers, "3", 1)).toBe("E3 exists already: edit it instead");
    expect(addConditionCommand(numbers, "0", 1)).toBe('A condition\'s number is a whole number from 1 to 99, not "0"');
    expect(addConditionCommand(numbers, "4.5", 1)).toBe('A condition\'s number is a whole number from 1 to 99, not "4.5"');
    expect(addConditionCommand(numbers, "", 1)).toBe('A condition\'s number is a whole number from 1 to 99, not ""');
    expect(addConditionCommand(numbers, "5", 7)).toBe("There is no E7 to copy");
  });
  it("asks before a delete and says what it costs", () => {
    expect(deleteQuestion(9)).toBe("Delete E9 from the profile? Programs that select it (M180 P9) will no longer open.");
  });
});

describe("a condition sequence", () => {
  const typed = { area: " 20 ", finish: "VDI18", undersize: "0.08", surface: "", depth: "" };
  it("asks for the area, the finish and the undersize, and for the program with a depth", () => {
    expect(sequenceQuery(typed)).toBe("area=20&finish=VDI18&undersize=0.08");
    expect(sequenceQuery({ ...typed, finish: "0.8", surface: "-20", depth: "0.1" })).toBe("area=20&finish=0.8&undersize=0.08&depth=0.1&surface=-20");
    expect(sequenceQuery({ ...typed, finish: "Ra1.6", depth: "0.1" })).toBe("area=20&finish=Ra1.6&undersize=0.08&depth=0.1&surface=0");
  });
  it("says in words what it will not ask", () => {
    expect(sequenceQuery({ ...typed, area: "0" })).toEqual({ error: `The electrode's frontal area (mm²) must be a number above 0, not "0"` });
    expect(sequenceQuery({ ...typed, finish: "fine" })).toEqual({ error: `The finish is an Ra in µm (0.8) or a VDI class (VDI18), not "fine"` });
    expect(sequenceQuery({ ...typed, undersize: "-0.1" })).toEqual({ error: `The undersize per side (mm) must be a number above 0, not "-0.1"` });
    expect(sequenceQuery({ ...typed, depth: "x" })).toEqual({ error: `The depth (mm) must be a number above 0, not "x"` });
    expect(sequenceQuery({ ...typed, depth: "0.1", surface: "top" })).toEqual({ error: `The surface is a position in mm, not "top"` });
  });
  it("shows a step's condition, finish, orbit and what is left for the next", () => {
    const step = { condition: 2, peak_current_a: 6, ra_um: 1.6, vdi: 24, side_gap_mm: 0.025, orbit_mm: 0.047, wall_mm: 0.072, allowance_mm: 0.008, removal_mm3_min: 4, wear_ratio: 0.03, orbit_limited: false };
    expect(sequenceCells(1, step)).toEqual(["2", "E2", "6", "1.6 (24)", "0.0250", "0.0470", "0.0720", "0.0080", "4", "3"]);
    expect(sequenceCells(0, { ...step, orbit_mm: 0 })[5]).toBe("-");
    expect(sequenceCells(0, { ...step, orbit_limited: true })[5]).toBe("0.0470 (its largest)");
    expect(sequenceCells(0, step).length).toBe(sequenceHeader.length);
  });
});
