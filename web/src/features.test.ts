// SPDX-License-Identifier: GPL-3.0-or-later
// The feature dialogs and panels: the power-fail recovery dialog through the power's return (what
// it offers in each state, each choice confirmed, the retract's inputs sent), the load hold, the
// process panels' lines, the tool check dialog, the retrace panel and the electrode setting screen.
import { describe, expect, it } from "vitest";
import { actionFields, question } from "./dialog_view";
import { recoveryPending } from "./dialogs/recovery";
import { splitDifferences, toolCheckMore, toolCheckText } from "./dialogs/toolcheck";
import { dialogFor } from "./dialogs/waits";
import { alarmLines, edmRows, loadBanner, loadText } from "./panels/process";
import { retraceControls, retraceText } from "./panels/retrace";
import { electrodeActions, resultLines } from "./screens/electrode";
import { seekText } from "./screens/jog";
import type { Status } from "./types";
import type { JournalState } from "./types_features";

const record = {
  valid: true, stage: "at-rest", program: "/x/broach-constant.ngc", file: "broach-constant.ngc", line: 11, segment: 3,
  segment_offset_mm: 543.2, move_remaining_mm: 179.8, actual: { X: 0.1, Z: 455.8, C: 279.5 }, tool: 0, spindle_rpm: 0,
  coupled: true, signal_time_s: 46.1, summary: "valid breakpoint",
};
const journal: JournalState = { record, phase: "none", recovery_error: "", write_error: "", can_resume: true, can_retract: true, mains_ok: true };
const base = {
  state: "idle", mode: "auto", wait: "", stop_reason: "", fault: "", job: { active: false },
  power: { monitor: true, mains_ok: true, on_battery: false, dc_link_v: 560 },
  features: { installed: ["journal"], journal },
} as unknown as Status;
const withJournal = (j: Partial<JournalState>, s: Partial<Status> = {}) =>
  ({ ...base, ...s, features: { installed: ["journal"], journal: { ...journal, ...j } } }) as Status;

describe("power-fail recovery dialog", () => {
  it("opens while a valid record waits and no choice acts on it", () => {
    expect(dialogFor(base)?.id).toBe("power-fail");
    expect(recoveryPending(withJournal({ phase: "resuming" }))).toBe(false);
    expect(dialogFor(withJournal({ record: { ...record, valid: false } }))).toBeUndefined();
    expect(dialogFor(withJournal({ record: null }))).toBeUndefined();
  });
  it("offers nothing while the mains are off, then reset and machine on", () => {
    const off = withJournal({}, { state: "faulted", power: { monitor: true, mains_ok: false, on_battery: false, dc_link_v: 0 } });
    const d = dialogFor(off)!;
    expect(d.id).toBe("power-fail");  // before the fault dialog
    expect(d.title(off)).toBe("Power failure");
    expect(d.text(off)).toContain("The mains are off");
    expect(d.actions(off)).toEqual([]);
    const back = withJournal({}, { state: "faulted" });
    expect(d.actions(back).map((a) => a.kind)).toEqual(["reset"]);
    expect(d.actions(withJournal({}, { state: "off" })).map((a) => a.kind)).toEqual(["machine-on"]);
  });
  it("shows what the record says and offers resume, retract and discard, each confirmed", () => {
    const d = dialogFor(base)!;
    expect(d.text(base)).toContain("broach-constant.ngc line 11 (segment 3)");
    expect(d.text(base)).toContain("Z 455.800");
    const actions = d.actions(base);
    expect(actions.map((a) => a.fields?.action)).toEqual(["resume", "retract", "discard"]);
    for (const a of actions) expect(a.confirm).toBeTruthy();
    expect(d.fields!(base).map((f) => f.name)).toEqual(
      ["tolerance_mm", "tolerance_deg", "run_in_mm", "run_in_speed_mm_min", "distance_mm", "direction", "speed_mm_min"]);
    const values = { tolerance_mm: 0.01, tolerance_deg: 0.01, run_in_mm: 2, run_in_speed_mm_min: 600, distance_mm: 2, direction: "onward", speed_mm_min: 50 };
    const retract = actions[1];
    expect(actionFields(retract, values, true)).toEqual({
      feature: "journal", action: "retract", distance_mm: 2, direction: "onward", speed_mm_min: 50, confirmed: true,
    });
    // Unconfirmed, a choice carries no confirmation (the server refuses it).
    expect(actionFields(actions[2], {}, false)).toEqual({ feature: "journal", action: "discard" });
  });
  it("shows the resume's tolerances and run-in from the profile, sends the operator's values and names them in the question", () => {
    const d = dialogFor(base)!;
    const s = withJournal({ can_retract: false, resume_defaults: { tolerance_mm: 0.02, tolerance_deg: 0.05, run_in_mm: 3, run_in_speed_mm_min: 400 } });
    expect(d.fields!(s).map((f) => [f.name, f.value])).toEqual(
      [["tolerance_mm", 0.02], ["tolerance_deg", 0.05], ["run_in_mm", 3], ["run_in_speed_mm_min", 400]]);
    const resume = d.actions(s)[0];
    expect(resume.fields?.action).toBe("resume");
    const values = { tolerance_mm: 0.05, tolerance_deg: 0.05, run_in_mm: 1.5, run_in_speed_mm_min: 400 };
    expect(actionFields(resume, values, true)).toEqual({
      feature: "journal", action: "resume", tolerance_mm: 0.05, tolerance_deg: 0.05, run_in_mm: 1.5, run_in_speed_mm_min: 400, confirmed: true,
    });
    expect(question(resume, d.fields!(s), values)).toBe(
      "Resume the program from the breakpoint, then on to its end (resume within 0.05 mm, and 0.05 °, run-in 1.5 mm, at 400 mm/min)");
    // Without the server's values: recovery::ResumeArgs' defaults.
    expect(d.fields!(withJournal({ can_retract: false })).map((f) => f.value)).toEqual([0.01, 0.01, 2, 600]);
  });
  it("offers only what the record allows, AUTO first when needed, and says why a choice failed", () => {
    const d = dialogFor(base)!;
    const stopping = withJournal({ can_resume: false, can_retract: false, phase: "failed", recovery_error: "Z is 0.5 mm from where it came to rest" },
      { mode: "manual" });
    expect(d.actions(stopping).map((a) => a.label)).toEqual(["AUTO mode", "Discard"]);
    expect(d.text(stopping)).toContain("The last choice failed: Z is 0.5 mm");
    expect(d.fields!(stopping)).toEqual([]);
  });
});

describe("load guard", () => {
  const load = { kn: 4.31, action: "hold", hold_kn: 4, retract_kn: 6 };
  it("shows a hold dialog with the load and the level, resume or abort", () => {
    const s = { ...base, features: undefined, state: "held", load } as unknown as Status;
    const d = dialogFor(s)!;
    expect(d.id).toBe("load-hold");
    expect(d.text(s)).toContain("hold level of 4 kN (now 4.31 kN)");
    expect(d.actions(s).map((a) => a.kind)).toEqual(["resume", "abort"]);
    expect(loadBanner(s)).toBe("Feed held: the load passed 4 kN. Check the cutter, then resume or abort.");
  });
  it("puts the load against its levels and says what a retract did", () => {
    const s = { ...base, load: { ...load, action: "lifted" } } as unknown as Status;
    expect(loadText(s)).toBe("Load 4.31 kN · hold 4 kN · retract 6 kN");
    expect(loadBanner(s)).toContain("the cutter lifted off the wall");
    expect(loadBanner({ ...s, load: { ...load, action: "none" } } as Status)).toBe("");
  });
});

describe("process panels", () => {
  it("lists the alarms with their state", () => {
    const s = { ...base, alarms: [{ name: "dielectric_level", active: true, reaction: "stop", low: 40, high: null, unit: "mm", value: 38.25 }] } as unknown as Status;
    expect(alarmLines(s)).toEqual([{ text: "dielectric_level: ALARM 38.25 mm (≥ 40 mm; stop)", active: true }]);
  });
  it("shows the EDM's gap against the reference, the discharge, jumps and depth", () => {
    const s = {
      ...base,
      edm: { on: true, generator: true, condition: 12, reference_v: 45, gap_state: "normal", gap_voltage_v: 44, filtered_voltage_v: 45.23,
        path_speed_mm_s: 0.012, backlog_mm: 0, retract_limit: false, jumping: false, jump_lift_mm: 0, jumps: 88, orbit_radius_mm: 0 },
      features: { installed: [], edm: { depth_mm: 0.109, burning: true } },
    } as unknown as Status;
    const rows = Object.fromEntries(edmRows(s));
    expect(rows.Condition).toBe("E12");
    expect(rows.Gap).toBe("45.2 V (ref 45 V)");
    expect(rows.Discharge).toBe("normal");
    expect(rows.Jumps).toBe("88");
    expect(rows.Depth).toBe("0.109 mm");
  });
});

describe("tool check dialog", () => {
  const check = { ok: false, error: "", backup: { id: 1, taken: "2026-11-26T09:56:24Z" },
    differences: ["T5 D1 length1: backup 193.225, live 139.225 (-54 mm; geometry tolerance 0.001 mm)"], report: "" };
  const held = { ...base, state: "running", job: { active: true, kind: "program" },
    features: { installed: ["tool-guard"], tool_guard: { store: "x.db", holding: true, check } } } as unknown as Status;
  it("lists the differences while the guard holds and asks before accept or restore", () => {
    const d = dialogFor(held)!;
    expect(d.id).toBe("tool-check");
    expect(d.text(held)).toContain("differ from backup 1 of 2026-11-26T09:56:24Z:\nT5 D1 length1: backup 193.225, live 139.225");
    const actions = d.actions(held);
    expect(actions.map((a) => a.fields?.action ?? a.kind)).toEqual(["check", "accept", "restore", "abort"]);
    expect(actions[1].confirm).toContain("new backup");
    expect(actions[2].confirm).toContain("Overwrite the live values with backup 1's");
    expect(actions[0].confirm).toBeUndefined();
  });
  it("lists the program's tools' differences first and folds the others", () => {
    const many = {
      ...check,
      differences: ["T1 D1 length1: backup 45, live 46 (…)", "T5 D1 length1: backup 193.225, live 139.225 (…)", "T9 D1 radius: backup 3, live 3.5 (…)"],
      difference_tools: [1, 5, 9],
    };
    const s = { ...held, features: { installed: ["tool-guard"], tool_guard: { store: "x.db", holding: true, check: many } } } as unknown as Status;
    expect(splitDifferences(s, [2, 5])).toEqual({ used: [many.differences[1]], rest: [many.differences[0], many.differences[2]] });
    const text = toolCheckText(s, [2, 5]);
    expect(text).toContain("differ from backup 1 of 2026-11-26T09:56:24Z in the program's tools (T2 T5):\nT5 D1 length1");
    expect(text).not.toContain("T9");
    expect(toolCheckMore(s, [2, 5])).toEqual({
      summary: "2 more differences in tools the program does not use", text: `${many.differences[0]}\n${many.differences[2]}`,
    });
    // The program's tools not known (no preview yet): every difference, nothing folded.
    expect(splitDifferences(s, []).rest).toEqual([]);
    expect(toolCheckMore(s, [])).toBeUndefined();
    // None of the program's tools differ: said so, the others below.
    expect(toolCheckText(s, [2])).toContain("(none of the program's tools; the others differ, below)");
  });
  it("is not shown when the guard does not hold", () => {
    expect(dialogFor({ ...held, features: { installed: ["tool-guard"], tool_guard: { store: "x.db", holding: false, check: null } } } as Status))
      .toBeUndefined();
  });
});

describe("retrace panel", () => {
  const at = (phase: string, active = true) => ({ ...base, job: { active, kind: "program" },
    features: { installed: ["retrace"], retrace: { phase, retraces: 0, last: null } } }) as unknown as Status;
  it("offers the pause while the program cuts, nothing while it stops", () => {
    expect(retraceControls(at("idle")).actions.map((a) => a.fields?.action)).toEqual(["pause"]);
    expect(retraceControls(at("idle", false)).actions).toEqual([]);
    expect(retraceControls(at("torch-off")).actions).toEqual([]);
    expect(retraceText(at("torch-off"))).toContain("the torch goes out");
  });
  it("steps back and on by the distance and cuts on from the nearest point, confirmed", () => {
    const { fields, actions } = retraceControls(at("paused"));
    expect(fields.map((f) => f.name)).toEqual(["distance_mm", "metric"]);
    const values = { distance_mm: 3, metric: "xyz" };
    expect(actionFields(actions[0], values, false)).toEqual({ feature: "retrace", action: "step", distance_mm: -3 });
    expect(actionFields(actions[1], values, false)).toEqual({ feature: "retrace", action: "step", distance_mm: 3 });
    expect(actions[2].confirm).toBeTruthy();
    expect(actionFields(actions[2], values, true)).toEqual({ feature: "retrace", action: "start", metric: "xyz", confirmed: true });
    expect(question(actions[2], fields, values)).toBe("Light the torch and cut on from the nearest point of the path? (nearest in xyz)");
  });
});

describe("electrode setting screen", () => {
  const result = { ok: true, code: "", message: "", tool: 1, touches: 5, previous: [0, 0, 0], offset: [0.05, -0.03, 0.2],
    rms_residual_mm: 0.0001, max_residual_mm: 0.0002, written: false };
  const at = (last: unknown, stopped = false) =>
    ({ ...base, features: { installed: ["electrode"], electrode: { phase: "idle", last, stopped_program: stopped } } }) as unknown as Status;
  it("shows the measured offsets against the table's and stores them only when confirmed", () => {
    expect(resultLines(result as never)).toEqual([
      "T1: 5 touches, fit residual 0.1 µm rms, 0.2 µm max",
      "measured  X 0.0500  Y -0.0300  Z 0.2000",
      "table     X 0.0000  Y 0.0000  Z 0.0000",
      "change    X 0.0500  Y -0.0300  Z 0.2000",
      "not stored yet: store the offsets to use them",
    ]);
    const [store] = electrodeActions(at(result));
    expect(store.fields).toEqual({ feature: "electrode", action: "write" });
    expect(store.confirm).toContain("Store T1's offsets X 0.0500  Y -0.0300  Z 0.2000 in the tool table");
  });
  it("offers the resume once stored, nothing after a failed measurement", () => {
    expect(electrodeActions(at({ ...result, written: true }, true)).map((a) => a.fields?.action)).toEqual(["resume"]);
    const failed = { ...result, ok: false, code: "electrode.far", message: "offsets 2 mm from the table's" };
    expect(electrodeActions(at(failed, true))).toEqual([]);
    expect(resultLines(failed as never)).toEqual(["T1: offsets 2 mm from the table's (electrode.far; nothing stored)"]);
  });
});

describe("seek of a limit switch on the jog screen", () => {
  it("shows the phase while a seek runs and what each found after", () => {
    const seek = (k: object) => ({ ...base, seek: k }) as unknown as Status;
    expect(seekText(seek({}))).toBe("");
    expect(seekText(seek({ X: { phase: "latch", direction: "+", found: false, tripped_at: 0, rest_at: 0 } }))).toBe(
      "X seeking its + limit: latch",
    );
    expect(
      seekText(seek({ X: { phase: "done", direction: "+", found: true, tripped_at: 151.0003, rest_at: 150 },
        Z: { phase: "failed", direction: "-", found: false, tripped_at: 0, rest_at: 0 } })),
    ).toBe("X + limit at 151.0003, backed off to 150.0000 · Z: the − limit switch was not found");
  });
});
