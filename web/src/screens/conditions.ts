// SPDX-License-Identifier: GPL-3.0-or-later
// The Machining conditions screen: an EDM's conditions ([[edm.condition]] of its profile) as a
// table — number, on/off time, peak current, voltage, polarity, servo reference, jump and orbit —
// with the one the generator runs now (the status' edm.condition) highlighted live.
import { registerScreen } from "../registry";
import type { Status } from "../types";
import { el } from "../ui";

/** One condition as GET /api/v1/conditions gives it. */
export interface Condition {
  number: number;
  on_time_us: number;
  off_time_us: number;
  peak_current_a: number;
  voltage_v: number;
  polarity: string;
  servo_reference_v: number;
  jump_height_mm: number;
  jump_period_s: number;
  jump_mode: string;
  orbit: string;
  orbit_radius_mm: number;
  orbit_step_mm: number;
}

/** The table's header: what each column of conditionCells() shows, with its unit. */
export const conditionHeader = ["E", "on µs", "off µs", "peak A", "voltage V", "polarity", "servo ref. V", "jump H mm / T s", "orbit"];

/** A condition's cells, in conditionHeader's order ("off" for a jump or an orbit that is off). */
export function conditionCells(c: Condition): string[] {
  const jump = c.jump_period_s > 0 ? `${c.jump_height_mm} / ${c.jump_period_s}${c.jump_mode === "path" ? " (path)" : ""}` : "off";
  const orbit = c.orbit === "none" ? "off" : `${c.orbit} ${c.orbit_radius_mm} mm${c.orbit_step_mm > 0 ? ` by ${c.orbit_step_mm}` : ""}`;
  return [`E${c.number}`, `${c.on_time_us}`, `${c.off_time_us}`, `${c.peak_current_a}`, `${c.voltage_v}`, c.polarity, `${c.servo_reference_v}`, jump, orbit];
}

/** The number of the condition in force (0: none: no EDM, or M181), from a status. */
export function activeCondition(s: Status | undefined): number {
  return s?.edm?.condition ?? 0;
}

let body: HTMLElement | undefined;
let note: HTMLElement | undefined;
let shown = -1;

function highlight(active: number) {
  if (!body || active === shown) return;
  shown = active;
  body.querySelectorAll("tr").forEach((tr) => tr.classList.toggle("active", Number(tr.dataset.condition) === active));
}

registerScreen({
  id: "conditions",
  title: "Conditions",
  mount(root) {
    body = el("tbody");
    note = el("p", { class: "hint" });
    const head = el("tr", {}, ...conditionHeader.map((h) => el("th", {}, h)));
    root.append(el("h2", {}, "Machining conditions"), note, el("table", { class: "grid", id: "conditions" }, el("thead", {}, head), body));
  },
  async shown(ctx) {
    const r = await ctx.api.get<{ profile: string; conditions: Condition[] }>("conditions");
    if (!body || !note) return;
    note.textContent =
      r.conditions.length === 0
        ? "This machine has no machining conditions (an EDM's [[edm.condition]] in its profile)."
        : `From ${r.profile}; M180 P<n> selects one in a program, M181 switches the generator off. The one in force is highlighted.`;
    body.replaceChildren(
      ...r.conditions.map((c) => {
        const tr = el("tr", {}, ...conditionCells(c).map((t) => el("td", {}, t)));
        tr.dataset.condition = `${c.number}`;
        return tr;
      }),
    );
    shown = -1;
    highlight(activeCondition(ctx.status()));
  },
  update(s) {
    highlight(activeCondition(s));
  },
});
