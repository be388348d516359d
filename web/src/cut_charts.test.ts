// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart screen's logic: a material's cells, who may edit, the operator's selection, the
// admin's edit checked on the page (each bad field named, nothing sent), a removal's question and
// the audit's lines.
import { describe, expect, it } from "vitest";
import {
  changeLine,
  chartHeader,
  editFields,
  materialBody,
  materialCells,
  mayEdit,
  removeQuestion,
  selectBody,
  type Material,
} from "./screens/cut_charts";

const mild6: Material = {
  number: 6,
  name: "Mild steel 6 mm 45 A",
  thickness_mm: 6,
  process: "plasma",
  kerf_width_mm: 1.5,
  feed_mm_min: 2400,
  pierce_height_mm: 3.8,
  pierce_delay_s: 0.5,
  cut_height_mm: 1.5,
  arc_voltage_v: 111.25,
  amperage_a: 45,
  puddle_height_mm: 0,
  puddle_delay_s: 0,
};

describe("cut chart", () => {
  it("shows a material in the header's order, an arc voltage of 0 as auto volts", () => {
    expect(materialCells(mild6)).toEqual(["6", "Mild steel 6 mm 45 A", "6", "plasma", "1.5", "2400", "3.8 / 0.5", "1.5", "111.25", "45"]);
    expect(materialCells(mild6).length).toBe(chartHeader.length);
    expect(materialCells({ ...mild6, arc_voltage_v: 0 })[8]).toBe("auto");
  });
  it("lets an admin edit and an operator only select", () => {
    expect(mayEdit("admin")).toBe(true);
    expect(mayEdit("operator")).toBe(false);
    expect(mayEdit(undefined)).toBe(false);
    expect(selectBody(6)).toEqual({ action: "select", material: 6 });
    expect(selectBody(0)).toEqual({ action: "select", material: 0 });
  });
  it("sends every field of an edited material, the typed ones as numbers", () => {
    const b = materialBody(mild6, { feed_mm_min: "2600", kerf_width_mm: " 1.6 " });
    expect(b).toEqual({ action: "set", material: { ...mild6, feed_mm_min: 2600, kerf_width_mm: 1.6, preheat_s: 0 } });
    expect(editFields).toContain("puddle_delay_s");
    expect(editFields).toContain("preheat_s");
    expect(editFields.length).toBe(14);
  });
  it("refuses a bad field on the page, naming it", () => {
    expect(materialBody(mild6, { cut_height_mm: "4" })).toBe("cut_height_mm: 4 is above the pierce height 3.8");
    expect(materialBody(mild6, { feed_mm_min: "fast" })).toBe('feed_mm_min: "fast" is not a number');
    expect(materialBody(mild6, { kerf_width_mm: "0" })).toBe("kerf_width_mm: 0 is not above 0 and at most 20");
    expect(materialBody(mild6, { pierce_delay_s: "-1" })).toBe("pierce_delay_s: -1 is not from 0 to 600");
    expect(materialBody(mild6, { process: "laser" })).toBe('process: plasma or oxy-fuel, not "laser"');
    expect(materialBody(mild6, { name: "  " })).toBe("name: a material needs a name");
    expect(materialBody({}, { number: "2.5" })).toBe('number: a whole number from 1 to 99999, not "2.5"');
    expect(materialBody(mild6, { puddle_delay_s: "0.2" })).toBe("puddle_delay_s: a puddle delay needs a puddle height");
  });
  it("keeps an oxy-fuel row's preheat, shows it, and refuses one on a plasma row", () => {
    const oxy = { ...mild6, number: 20, process: "oxy-fuel", pierce_height_mm: 12, cut_height_mm: 7, preheat_s: 0 };
    expect(materialBody(oxy, { preheat_s: "6.5" })).toEqual({ action: "set", material: { ...oxy, preheat_s: 6.5 } });
    expect(materialCells({ ...oxy, preheat_s: 6.5 })[6]).toBe("12 / 0.5 · preheat 6.5 s");
    expect(materialCells(oxy)[6]).toBe("12 / 0.5 · preheat profile's");
    expect(materialBody(oxy, { preheat_s: "-2" })).toBe("preheat_s: -2 is not from 0 to 600");
    expect(materialBody(mild6, { preheat_s: "3" })).toBe("preheat_s: a plasma material has no preheat (oxy-fuel only)");
  });
  it("makes a new material from what is typed", () => {
    const typed = { number: "12", name: "Aluminium 3", process: "plasma", thickness_mm: "3", kerf_width_mm: "1.6", feed_mm_min: "4000", pierce_height_mm: "3.5", pierce_delay_s: "0.2", cut_height_mm: "1.5", arc_voltage_v: "0", amperage_a: "45", puddle_height_mm: "0", puddle_delay_s: "0" };
    const b = materialBody({}, typed) as { material: Material };
    expect(b.material.number).toBe(12);
    expect(b.material.arc_voltage_v).toBe(0);
  });
  it("asks before a removal and shows the audit old → new", () => {
    expect(removeQuestion(mild6)).toBe("Remove material 6 (Mild steel 6 mm 45 A) from the cut chart? Programs that select it (M194 P6) will no longer open.");
    expect(changeLine({ at_utc: "2026-12-07T16:00:10Z", interface: "hmi", reason: "set", what: "material 6 feed_mm_min", old: "2400", new: "2600" })).toBe(
      "2026-12-07T16:00:10Z hmi material 6 feed_mm_min: 2400 → 2600",
    );
    expect(changeLine({ at_utc: "t", interface: "command line", reason: "import", what: "material 3", old: "", new: "name=…" })).toBe("t command line material 3: (none) → name=…");
  });
});
