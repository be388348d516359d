// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma cutting panel: the torch's phase, the height control's state (and whether it is
// locked), the arc voltage against its target, the torch height, arc-OK and the torch output, from
// the status' `features.cutting` (docs/cutting.md, docs/hmi.md "Cutting").
import { registerPanel } from "../registry";
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
  };
  const cutting = c.phase === "cutting";
  return { text: cutting ? words[c.thc] ?? c.thc : "—", locked: cutting && kLocks.includes(c.thc) };
}

/** The panel's rows: label and value. */
export function cuttingRows(s: Status): [string, string][] {
  const c = s.features!.cutting!;
  const target = c.target_voltage_v > 0 ? ` (target ${c.target_voltage_v.toFixed(1)} V)` : "";
  const height = c.phase === "off" ? "—" : `${c.thc_offset_mm.toFixed(2)} mm offset` +
    (c.phase === "cutting" ? ` · correction ${c.correction_mm >= 0 ? "+" : ""}${c.correction_mm.toFixed(2)} mm` : "");
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
    root.append(el("h3", {}, "Plasma"), el("table", { class: "grid cutting" }));
  },
  update(s, root) {
    if (!s.features?.cutting) return false;
    const table = root.querySelector("table")!;
    const c = s.features.cutting;
    table.dataset.testid = "cutting-panel";
    table.replaceChildren(...cuttingRows(s).map(([k, v]) => {
      const row = el("tr", {}, el("th", {}, k), el("td", {}, v));
      if (k === "THC" && thcText(c).locked) row.classList.add("warning");
      if (k === "Torch" && c.torch_on) row.classList.add("on");
      return row;
    }));
    return true;
  },
});
