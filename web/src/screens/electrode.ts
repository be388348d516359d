// SPDX-License-Identifier: GPL-3.0-or-later
// Electrode setting (an EDM with a reference sphere): run the routine on the sphere for a tool,
// see the measured offsets beside the table's, store them on confirmation, and resume a program
// that stopped for the new electrode (docs/electrode-setting.md).
import { renderActions } from "../dialog_view";
import { registerScreen, type DialogAction } from "../registry";
import type { Status } from "../types";
import type { ElectrodeResult } from "../types_features";
import { button, el } from "../ui";

const xyz = (p: number[]) => `X ${p[0].toFixed(4)}  Y ${p[1].toFixed(4)}  Z ${p[2].toFixed(4)}`;

/** The last measurement in words: the offsets measured against the table's, the fit, stored or not. */
export function resultLines(r: ElectrodeResult): string[] {
  if (!r.ok) return [`T${r.tool}: ${r.message} (${r.code}; nothing stored)`];
  const d = r.offset.map((v, i) => v - r.previous[i]);
  return [
    `T${r.tool}: ${r.touches} touches, fit residual ${(r.rms_residual_mm * 1000).toFixed(1)} µm rms, ${(r.max_residual_mm * 1000).toFixed(1)} µm max`,
    `measured  ${xyz(r.offset)}`,
    `table     ${xyz(r.previous)}${r.written ? " (before)" : ""}`,
    `change    ${xyz(d)}`,
    r.written ? "stored in the tool table" : "not stored yet: store the offsets to use them",
  ];
}

/** The buttons the last measurement allows: store it (confirmed), resume the stopped program (confirmed). */
export function electrodeActions(s: Status): DialogAction[] {
  const e = s.features?.electrode;
  if (!e || e.phase !== "idle") return [];
  const out: DialogAction[] = [];
  const r = e.last;
  if (r?.ok && !r.written)
    out.push({ label: "Store the offsets", kind: "feature", fields: { feature: "electrode", action: "write" }, cls: "go",
      confirm: `Store T${r.tool}'s offsets ${xyz(r.offset)} in the tool table (they were ${xyz(r.previous)})?` });
  if (e.stopped_program && r?.ok && r.written)
    out.push({ label: "Resume the program", kind: "feature", fields: { feature: "electrode", action: "resume" },
      confirm: "Resume the stopped program with the new electrode (an approach to where it stopped, moved by the change of offsets)?" });
  return out;
}

let drawn = "";
registerScreen({
  id: "electrode",
  title: "Electrode",
  requires: "electrode",
  mount(root, ctx) {
    const tool = el("input", { type: "number", class: "num", min: "1", value: "1" });
    tool.dataset.testid = "electrode-tool";
    const measure = button("Measure on the sphere", () => void ctx.send("feature", { feature: "electrode", action: "measure", tool: Number(tool.value) }), "go");
    measure.dataset.testid = "electrode-measure";
    root.append(el("h2", {}, "Electrode setting"),
      el("p", { class: "hint" }, "The electrode touches the reference sphere; its offsets are shown, then stored when you confirm."),
      el("div", { class: "row" }, el("span", {}, "Tool "), tool, measure), el("p", { class: "phase" }), el("pre", { class: "result" }),
      el("div", { class: "row actions" }));
  },
  update(s, ctx) {
    const e = s.features?.electrode;
    const root = document.querySelector('[data-screen-root="electrode"]') as HTMLElement | null;
    if (!e || !root) return;
    root.querySelector(".phase")!.textContent = e.phase === "idle" ? "" : `Electrode setting: ${e.phase}…`;
    root.querySelector(".result")!.textContent = e.last ? resultLines(e.last).join("\n") : "No measurement yet.";
    const actions = electrodeActions(s);
    const key = `${e.phase}|${JSON.stringify(e.last)}|${actions.map((a) => a.label).join(",")}`;
    if (key !== drawn) {
      drawn = key;
      renderActions(root.querySelector(".actions") as HTMLElement, actions, [], {}, (kind, f) => ctx.send(kind, f));
    }
  },
});
