// SPDX-License-Identifier: GPL-3.0-or-later
// The power-fail recovery dialog (a valid breakpoint in the journal: resume, retract, discard,
// each confirmed) and the broaching load hold (docs/hmi.md, "Dialogs"; docs/broaching.md).
import { registerDialog, type DialogAction } from "../registry";
import type { Status } from "../types";
import type { JournalState } from "../types_features";

/** The resume's values when the server sends none (recovery::ResumeArgs' defaults). */
const kResumeDefaults = { tolerance_mm: 0.01, tolerance_deg: 0.01, run_in_mm: 2, run_in_speed_mm_min: 600 };
const kResumeFields = ["tolerance_mm", "tolerance_deg", "run_in_mm", "run_in_speed_mm_min"];
const kRetractFields = ["distance_mm", "direction", "speed_mm_min"];

/** A choice's own inputs out of the dialog's (resume and retract share the form). */
function pick(names: string[]) {
  return (values: Record<string, number | string>) => Object.fromEntries(names.filter((n) => n in values).map((n) => [n, values[n]]));
}

/** The phases in which a recovery choice is under way (the dialog steps aside meanwhile). */
const busy = ["opening", "running-in", "resuming", "retracting"];

function journal(s: Status): JournalState | undefined {
  return s.features?.journal;
}

/** Whether the journal holds a valid breakpoint that no choice is acting on. */
export function recoveryPending(s: Status): boolean {
  const j = journal(s);
  return !!j?.record?.valid && !busy.includes(j.phase);
}

/** What the record says, for the operator, in a few lines. */
export function recordText(s: Status): string {
  const r = journal(s)!.record!;
  const at = Object.entries(r.actual).map(([a, v]) => `${a} ${v.toFixed(3)}`).join("  ");
  return `${r.program.split("/").pop()} line ${r.line} (segment ${r.segment}), ${r.move_remaining_mm.toFixed(1)} mm of the move left; ` +
    `the axes rest at ${at}${r.coupled ? "; the coupling law held" : ""}. Stage: ${r.stage}.`;
}

registerDialog({
  id: "power-fail",
  wants: recoveryPending,
  title: (s) => (s.power && !s.power.mains_ok ? "Power failure" : "Recovery after the power failure"),
  text: (s) => {
    const j = journal(s)!;
    const failed = j.phase === "failed" && j.recovery_error ? ` The last choice failed: ${j.recovery_error}.` : "";
    if (s.power && (!s.power.mains_ok || s.power.on_battery))
      return `${recordText(s)} The mains are off: the choices are offered once the power returns.`;
    if (s.state === "faulted" || s.state === "off" || s.state === "e-stopped")
      return `${recordText(s)} The power is back: reset and switch the machine on, then choose.${failed}`;
    const offer = [j.can_resume ? "resume the program from the breakpoint" : "",
      j.can_retract ? "retract the cutter along the helix" : "", "discard the breakpoint"].filter((x) => x).join(", ");
    const auto = s.mode !== "auto" ? " Resume needs AUTO mode." : "";
    return `${recordText(s)} You may ${offer}.${auto}${failed}`;
  },
  fields: (s) => {
    const j = journal(s);
    if (!j || s.state !== "idle") return [];
    const d = j.resume_defaults ?? kResumeDefaults;
    return [
      ...(j.can_resume ? [
        { name: "tolerance_mm", label: "Resume within", value: d.tolerance_mm, unit: "mm" },
        { name: "tolerance_deg", label: "and", value: d.tolerance_deg, unit: "°" },
        { name: "run_in_mm", label: "run-in", value: d.run_in_mm, unit: "mm" },
        { name: "run_in_speed_mm_min", label: "at", value: d.run_in_speed_mm_min, unit: "mm/min" }] : []),
      ...(j.can_retract ? [
        { name: "distance_mm", label: "Distance", value: 5, unit: "mm" },
        { name: "direction", label: "direction", value: "back", options: ["back", "onward"] },
        { name: "speed_mm_min", label: "at", value: 100, unit: "mm/min" }] : []),
    ];
  },
  actions: (s) => {
    const j = journal(s)!;
    if (s.power && (!s.power.mains_ok || s.power.on_battery)) return [];
    if (s.state === "faulted" || s.state === "e-stopped") return [{ label: "Reset", kind: "reset", cls: "go" }];
    if (s.state === "off") return [{ label: "Machine on", kind: "machine-on", cls: "go" }];
    const feature = (action: string, label: string, confirm: string, extra: Partial<DialogAction> = {}): DialogAction =>
      ({ label, kind: "feature", fields: { feature: "journal", action }, confirm, ...extra });
    const out: DialogAction[] = [];
    if (s.mode !== "auto") out.push({ label: "AUTO mode", kind: "mode", fields: { mode: "auto" } });
    if (j.can_resume)
      out.push(feature("resume", "Resume", "Resume the program from the breakpoint, then on to its end", { cls: "go", form: true, transform: pick(kResumeFields) }));
    if (j.can_retract) out.push(feature("retract", "Retract", "Retract the cutter", { form: true, transform: pick(kRetractFields) }));
    out.push(feature("discard", "Discard", "Discard the breakpoint? The program cannot be resumed from it afterwards.", { cls: "danger" }));
    return out;
  },
});

registerDialog({
  id: "load-hold",
  wants: (s) => s.state === "held" && s.load?.action === "hold",
  title: () => "Broaching load: feed hold",
  text: (s) => `The load passed the hold level of ${s.load!.hold_kn} kN (now ${s.load!.kn.toFixed(2)} kN): the feed is held on the path, ` +
    "the coupled axis on its law. Check the cutter; resume cuts on (the guard holds again if the load passes the level again), " +
    "or abort the run.",
  actions: () => [{ label: "Resume", kind: "resume", cls: "go" }, { label: "Abort", kind: "abort", cls: "danger" }],
});
