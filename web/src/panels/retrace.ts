// SPDX-License-Identifier: GPL-3.0-or-later
// The retrace panel of a flame or plasma cutter (not a modal dialog: while the cut is paused the
// operator jogs the torch with F1): pause the cut, step along the path or jog off it, then go
// back to the nearest point of the path and cut on — confirmed (docs/retrace.md).
import { renderActions, renderFields } from "../dialog_view";
import { registerPanel, type DialogAction, type DialogField } from "../registry";
import type { Status } from "../types";
import { el } from "../ui";

/** What the panel says in each phase. */
export function retraceText(s: Status): string {
  const r = s.features!.retrace!;
  switch (r.phase) {
    case "idle":
      return s.job.active && s.job.kind === "program" ? "Retrace: pause the cut to move the torch off the path." : "Retrace: idle.";
    case "holding": case "stopping": case "torch-off":
      return "Retrace: stopping on the path, the torch goes out…";
    case "paused":
      return "Retrace: the cut is paused. Jog the torch off the path (F1, MANUAL) or step along it, then cut on from the nearest point of the path.";
    case "stepping":
      return "Retrace: moving along the path…";
    case "approaching":
      return "Retrace: back to the path, the torch lit again…";
    case "cutting": {
      const l = r.last;
      return l ? `Retrace: cutting on from ${l.line} (${l.distance_mm.toFixed(1)} mm from where the torch stood).` : "Retrace: cutting on.";
    }
    default:
      return `Retrace: ${r.phase}`;
  }
}

/** The controls of a phase: its inputs and buttons. */
export function retraceControls(s: Status): { fields: DialogField[]; actions: DialogAction[] } {
  const r = s.features!.retrace!;
  const retrace = (action: string) => ({ feature: "retrace", action });
  if (r.phase === "idle" && s.job.active && s.job.kind === "program")
    return { fields: [], actions: [{ label: "Pause for retrace", kind: "feature", fields: retrace("pause"), cls: "danger" }] };
  if (r.phase !== "paused") return { fields: [], actions: [] };
  return {
    fields: [{ name: "distance_mm", label: "Step", value: 5, unit: "mm" },
      { name: "metric", label: "nearest in", value: "xy", options: ["xy", "xyz"] }],
    actions: [
      { label: "Step back", kind: "feature", fields: retrace("step"), form: true, transform: (v) => ({ distance_mm: -Math.abs(Number(v.distance_mm)) }) },
      { label: "Step on", kind: "feature", fields: retrace("step"), form: true, transform: (v) => ({ distance_mm: Math.abs(Number(v.distance_mm)) }) },
      { label: "Cut on from the nearest point", kind: "feature", fields: retrace("start"), form: true, cls: "go",
        transform: (v) => ({ metric: v.metric }), confirm: "Light the torch and cut on from the nearest point of the path?" },
    ],
  };
}

let drawn = "";
registerPanel({
  id: "retrace",
  mount(root) {
    root.append(el("h3", {}, "Retrace"), el("p", { class: "hint" }), el("div", {}), el("div", { class: "row" }));
  },
  update(s, root, ctx) {
    if (!s.features?.retrace) return false;
    root.querySelector("p")!.textContent = retraceText(s);
    const { fields, actions } = retraceControls(s);
    const key = `${s.features.retrace.phase}|${actions.map((a) => a.label).join(",")}`;
    if (key !== drawn) {
      drawn = key;
      const values: Record<string, number | string> = {};
      const [inputs, row] = [root.children[2] as HTMLElement, root.children[3] as HTMLElement];
      inputs.replaceChildren(...(fields.length ? [renderFields(fields, values)] : []));
      renderActions(row, actions, fields, values, (kind, f) => ctx.send(kind, f));
    }
    return true;
  },
});
