// SPDX-License-Identifier: GPL-3.0-or-later
// The formats of the DRO and the overrides, and which dialog a status asks for.
import { describe, expect, it } from "vitest";
import { coord, offsetsText, outsideWindow, percent, topBarLooks, windowStart } from "./ui";
import { dialogFor } from "./dialogs/waits";
import type { Status } from "./types";

describe("formats", () => {
  it("shows coordinates with a sign and three decimals, no negative zero", () => {
    expect(coord(12.34567)).toBe("+12.346");
    expect(coord(-0.0001)).toBe("+0.000");
    expect(coord(-3)).toBe("-3.000");
    expect(coord(undefined)).toBe("—");
  });
  it("says which offsets hold, only the axes that have one", () => {
    const o = { system: "G55", g5x: { X: 10, Y: 20, Z: 0 }, g92: { X: 1, Y: 0, Z: 0 }, tool: { X: 0, Y: 0, Z: 0 }, xy_rotation_deg: 0 };
    expect(offsetsText(o, ["X", "Y", "Z"])).toBe("G55 X+10.000 Y+20.000 · G92 X+1.000");
    expect(offsetsText({ ...o, g5x: {}, g92: {} }, ["X"])).toBe("G55");
  });
  it("pages the listing around the current line", () => {
    expect(windowStart(1, 2000)).toBe(1);
    expect(windowStart(10000, 2000)).toBe(9500);
    expect(outsideWindow(0, 1, 2000, true)).toBe(false);
    expect(outsideWindow(1999, 1, 2000, true)).toBe(false);
    expect(outsideWindow(2001, 1, 2000, true)).toBe(true);
    expect(outsideWindow(2001, 1, 2000, false)).toBe(false);  // past the file's end: nothing to load
    expect(outsideWindow(10, 9500, 2000, true)).toBe(true);
  });
  it("shows overrides in per cent", () => {
    expect(percent(1.2)).toBe("120 %");
  });
});

describe("the top bar's buttons", () => {
  it("show the machine on as pressed and have nothing to do there", () => {
    const on = topBarLooks("idle", "manual");
    expect(on["machine-on"]).toEqual({ on: true, disabled: true, title: "the machine is on" });
    expect(on["machine-off"].disabled).toBe(false);
    expect(on.manual).toEqual({ on: true, disabled: true, title: "in MANUAL mode" });
    expect(on.auto).toEqual({ on: false, disabled: false, title: "" });
    expect(on.reset.disabled).toBe(true);
  });
  it("say what comes first when the machine cannot be turned on", () => {
    expect(topBarLooks("e-stopped", "manual")["machine-on"]).toEqual({ on: false, disabled: true, title: "reset the e-stop first" });
    expect(topBarLooks("e-stopped", "manual").reset.disabled).toBe(false);
    expect(topBarLooks("e-stopped", "manual").estop.on).toBe(true);
    expect(topBarLooks("off", "manual")["machine-on"].disabled).toBe(false);
    expect(topBarLooks("off", "manual")["machine-off"]).toEqual({ on: true, disabled: true, title: "the machine is off" });
  });
  it("keep the mode while a program runs", () => {
    expect(topBarLooks("running", "auto").manual).toEqual({ on: false, disabled: true, title: "the mode changes while nothing runs" });
  });
});

describe("dialogs", () => {
  const base = { state: "running", wait: "", stop_reason: "", fault: "", job: { active: true } } as unknown as Status;
  it("asks for the tool at a manual tool change", () => {
    expect(dialogFor({ ...base, wait: "manual-tool-change" })?.id).toBe("tool-change");
  });
  it("asks to continue at M0 and M1, and after feed hold", () => {
    expect(dialogFor({ ...base, state: "stopped", stop_reason: "program-stop" })?.id).toBe("program-stop");
    expect(dialogFor({ ...base, state: "held" })?.id).toBe("feed-hold");
  });
  it("shows a fault and nothing while the program simply runs", () => {
    expect(dialogFor({ ...base, state: "faulted", fault: "following error on X" })?.id).toBe("fault");
    expect(dialogFor(base)).toBeUndefined();
  });
});
