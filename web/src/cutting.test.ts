// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma cutting panel's rows (torch, arc-OK, voltage against its target, height, THC and its
// locks) and the torch's hold dialog (an arc lost or a failed start: retrace, resume, abort; not
// while the retrace acts, nor on an operator's feed hold).
import { describe, expect, it } from "vitest";
import "./dialogs/torch_hold";
import { dialogFor } from "./dialogs/waits";
import { cuttingActions, cuttingRows, preheatText, thcText } from "./panels/cutting";
import type { Status } from "./types";
import type { CuttingState } from "./types_features";

const cutting: CuttingState = {
  phase: "cutting", thc: "active", torch_on: true, arc_ok: true, sensor: false, arc_voltage_v: 111.26,
  target_voltage_v: 111.3, thc_offset_mm: -16.4, correction_mm: 0.123, plate_z_mm: -2.1, pierces: 4, arc_losses: 0,
  hold_reason: "",
};
const at = (c: Partial<CuttingState>, s: Partial<Status> = {}, retrace = "idle") =>
  ({
    state: "running", mode: "auto", wait: "", wait_text: "", stop_reason: "", fault: "", job: { active: true, kind: "program" },
    ...s,
    features: { installed: ["cutting", "retrace"], cutting: { ...cutting, ...c }, retrace: { phase: retrace, retraces: 0, last: null } },
  }) as unknown as Status;

describe("cutting panel", () => {
  it("shows the torch, arc-OK, the voltage against its target, the height and the height control", () => {
    const rows = Object.fromEntries(cuttingRows(at({})));
    expect(rows["Torch"]).toBe("ON · cutting");
    expect(rows["Arc-OK"]).toBe("yes");
    expect(rows["Arc voltage"]).toBe("111.3 V (target 111.3 V)");
    expect(rows["Height"]).toBe("-16.40 mm offset · correction +0.12 mm");
    expect(rows["THC"]).toBe("following the plate");
    expect(rows["Cut"]).toBe("4 pierces · 0 arc losses");
  });
  it("says when the height control is locked, and why", () => {
    expect(thcText({ ...cutting, thc: "program-lock" })).toEqual({ text: "locked (hole or M192)", locked: true });
    expect(thcText({ ...cutting, thc: "void-lock" }).locked).toBe(true);
    expect(thcText({ ...cutting, thc: "corner-lock" }).text).toBe("locked (corner)");
    expect(thcText({ ...cutting, thc: "active" }).locked).toBe(false);
    expect(thcText({ ...cutting, phase: "piercing", thc: "off" })).toEqual({ text: "—", locked: false });
    expect(Object.fromEntries(cuttingRows(at({ phase: "off", torch_on: false, target_voltage_v: 0 })))["Height"]).toBe("—");
  });
});

describe("cutting panel, oxy-fuel", () => {
  const oxy: Partial<CuttingState> = {
    process: "oxy-fuel", phase: "preheating", thc: "off", torch_on: true, arc_ok: false, arc_voltage_v: 0, target_voltage_v: 0,
    cut_oxygen: false, waiting_start: true, sensor_height_mm: 7.02, preheat_s: 5.43, preheats: 2, thc_offset_mm: -12.5,
  };
  it("shows the preheat waiting for the operator and offers Start cut", () => {
    const rows = Object.fromEntries(cuttingRows(at(oxy)));
    expect(rows["Torch"]).toBe("ON · preheating");
    expect(rows["Cutting oxygen"]).toBe("off");
    expect(rows["Preheat"]).toBe("5.4 s · waiting for Start cut");
    expect(rows["Height sensor"]).toBe("7.02 mm");
    expect(rows["Arc voltage"]).toBeUndefined();
    expect(rows["Cut"]).toBe("4 pierces · 2 preheats");
    expect(cuttingActions(at(oxy))).toEqual([{ label: "Start cut", kind: "start-cut", cls: "go" }]);
  });
  it("offers Start cut during a timed preheat too, and not once the cut runs", () => {
    expect(preheatText({ ...cutting, ...oxy, waiting_start: false } as CuttingState)).toBe("5.4 s · by time (Start cut ends it now)");
    expect(cuttingActions(at({ ...oxy, waiting_start: false })).map((a) => a.kind)).toEqual(["start-cut"]);
    const cut = at({ ...oxy, phase: "cutting", thc: "void-lock", waiting_start: false, cut_oxygen: true });
    expect(cuttingActions(cut)).toEqual([]);
    const rows = Object.fromEntries(cuttingRows(cut));
    expect(rows["Cutting oxygen"]).toBe("ON");
    expect(rows["Preheat"]).toBe("last 5.4 s");
    expect(rows["THC"]).toBe("locked (kerf or plate edge)");
    expect(cuttingActions(at({}))).toEqual([]);  // plasma: no preheat, no button
  });
});

describe("torch hold dialog", () => {
  it("after an arc loss offers retrace, resume here and abort", () => {
    const s = at({ phase: "paused", torch_on: false, arc_ok: false, arc_losses: 1, hold_reason: "arc-lost" }, { state: "held" });
    const d = dialogFor(s)!;
    expect(d.id).toBe("torch-hold");
    expect(d.title(s)).toBe("Arc lost");
    expect(d.text(s)).toContain("Retrace to go back along the path");
    const actions = d.actions(s);
    expect(actions.map((a) => a.label)).toEqual(["Retrace", "Resume here", "Abort"]);
    expect(actions[0]).toMatchObject({ kind: "feature", fields: { feature: "retrace", action: "pause" } });
  });
  it("says so after failed starts, and offers no retrace on a machine without it", () => {
    const s = at({ phase: "failed", torch_on: false, hold_reason: "failed" }, { state: "held" });
    expect(dialogFor(s)!.title(s)).toBe("Torch start failed");
    const bare = { ...s, features: { installed: ["cutting"], cutting: s.features!.cutting } } as Status;
    expect(dialogFor(bare)!.actions(bare).map((a) => a.label)).toEqual(["Resume here", "Abort"]);
  });
  it("names a breakaway and a torch that touched the plate, with the same choices", () => {
    const knocked = at({ phase: "paused", torch_on: false, hold_reason: "breakaway" }, { state: "held" });
    expect(dialogFor(knocked)!.title(knocked)).toBe("Torch breakaway");
    expect(dialogFor(knocked)!.text(knocked)).toContain("Seat the torch first");
    expect(dialogFor(knocked)!.actions(knocked).map((a) => a.label)).toEqual(["Retrace", "Resume here", "Abort"]);
    const touched = at({ phase: "paused", torch_on: false, hold_reason: "float" }, { state: "held" });
    expect(dialogFor(touched)!.title(touched)).toBe("Torch touched the plate");
  });
  it("steps aside for the operator's feed hold and while the retrace acts", () => {
    const hold = at({ phase: "paused", torch_on: false }, { state: "held" });
    expect(dialogFor(hold)!.id).toBe("feed-hold");
    const retracing = at({ phase: "paused", hold_reason: "arc-lost" }, { state: "held" }, "holding");
    expect(dialogFor(retracing)?.id).not.toBe("torch-hold");
    expect(dialogFor(at({}))).toBeUndefined();
  });
});
