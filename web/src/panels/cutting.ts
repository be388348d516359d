// SPDX-License-Identifier: GPL-3.0-or-later
// The cutting panel: the torch's phase, the height control's state (and whether it is locked),
// the arc voltage against its target (plasma) or the height sensor's reading and the preheat
// (oxy-fuel, with "Start cut" while a preheat is under way), the torch height, arc-OK and the
// torch output, from the status' `features.cutting` (docs/cutting.md, docs/hmi.md "Cutting").
import { renderActions } from "../dialog_view";
import { registerPanel, type DialogAction } from "../registry";
import type { Status } from "../types";
import type { CuttingState } from "../types_features";
import { el } from "../ui";

/** The height control's states that hold the height (the torch does not follow the voltage). */
const kLocks = ["corner-lock", "anti-dive", "void-lock", "program-lock", "waiting", "off"];

/** What the height control does, in words; `locked` when it holds the height. */
export function thcText(c: CuttingState): { text: string; locked: boolean } {
  const words: Record<string, string> = {
    off: "off", waiting: "waiting", sampling: "sampling the voltage", active: "following the plate",
    "corner-lock": "locked (corner)", "anti-dive": "locked (braking)", "void-lock": "locked (kerf or void)",
    "program-lock": "locked (hole or M192)",
    ...(c.process === "oxy-fuel" ? { "void-lock": "locked (kerf or plate edge)" } : {}),
  };
  const cutting = c.phase === "cutting";
  return { text: cutting ? words[c.thc] ?? c.thc : "—", locked: cutting && kLocks.includes(c.thc) };
}

export const oxyFuel = (c: CuttingState) => c.process === "oxy-fuel";

/** The preheat in words: how long so far, and whether it waits for the operator's start. */
export function preheatText(c: CuttingState): string {
  const t = `${(c.preheat_s ?? 0).toFixed(1)} s`;
  if (c.phase !== "preheating") return (c.preheats ?? 0) > 0 ? `last ${t}` : "—";
  return c.waiting_start ? `${t} · waiting for Start cut` : `${t} · by time (Start cut ends it now)`;
}

/** The panel's buttons: "Start cut" while an oxy-fuel preheat is under way. */
export function cuttingActions(s: Status): DialogAction[] {
  const c = s.features!.cutting!;
  if (!oxyFuel(c) || c.phase !== "preheating") return [];
  return [{ label: "Start cut", kind: "start-cut", cls: "go" }];
}

/** The panel's rows: label and value. */
export function cuttingRows(s: Status): [string, string][] {
  const c = s.features!.cutting!;
  const target = c.target_voltage_v > 0 ? ` (target ${c.target_voltage_v.toFixed(1)} V)` : "";
  const height = c.phase === "off" ? "—" : `${c.thc_offset_mm.toFixed(2)} mm offset` +
    (c.phase === "cutting" ? ` · correction ${c.correction_mm >= 0 ? "+" : ""}${c.correction_mm.toFixed(2)} mm` : "");
  if (oxyFuel(c))
    return [
      ["Torch", `${c.torch_on ? "ON" : "off"} · ${c.phase}`],
      ["Cutting oxygen", c.cut_oxygen ? "ON" : "off"],
      ["Preheat", preheatText(c)],
      ["Height sensor", `${(c.sensor_height_mm ?? 0).toFixed(2)} mm`],
      ["Height", height],
      ["THC", thcText(c).text],
      ["Cut", `${c.pierces} pierces · ${c.preheats ?? 0} preheats`],
    ];
  return [
    ["Torch", `${c.torch_on ? "ON" : "off"} · ${c.phase}`],
    ["Arc-OK", c.arc_ok ? "yes" : "no"],
    ["Arc voltage", `${c.arc_voltage_v.toFixed(1)} V${target}`],
    ["Height", height],
    ["THC", thcText(c).text],
    ["Cut", `${c.pierces} pierces · ${c.arc_losses} arc losses`],
  ];
}

registerPanel({
  id: "cutting",
  mount(root) {
    root.append(el("h3", {}, "Plasma"), el("table", { class: "grid cutting" }), el("div", { class: "row" }));
  },
  update(s, root, ctx) {
    if (!s.features?.cutting) return false;
    const table = root.querySelector("table")!;
    const c = s.features.cutting;
    root.querySelector("h3")!.textContent = oxyFuel(c) ? "Oxy-fuel" : "Plasma";
    const actions = cuttingActions(s);
    const buttons = root.querySelector("div.row") as HTMLElement;
    const key = actions.map((a) => a.label).join(",");
    if (buttons.dataset.drawn !== key) {
      buttons.dataset.drawn = key;
      renderActions(buttons, actions, [], {}, (kind, f) => ctx.send(kind, f));
    }
    table.dataset.testid = "cutting-panel";
    table.replaceChildren(...cuttingRows(s).map(([k, v]) => {
      const row = el("tr", {}, el("th", {}, k), el("td", {}, v));
      if (k === "THC" && thcText(c).locked) row.classList.add("warning");
      if ((k === "Torch" && c.torch_on) || (k === "Cutting oxygen" && c.cut_oxygen)) row.classList.add("on");
      if (k === "Preheat" && c.waiting_start) row.classList.add("warning");
      return row;
    }));
    return true;
  },
});
