// SPDX-License-Identifier: GPL-3.0-or-later
// The main screen's process panels: the broach's load against its levels (with a banner when
// the guard acted and what the operator may do), the process alarms, and the EDM's live values
// (gap voltage against the condition's reference, discharge state, generator, jumps, depth).
import { registerPanel } from "../registry";
import type { Status } from "../types";
import { el } from "../ui";

/** The load line: "Load 2.87 kN · hold 4 kN · retract 6 kN". */
export function loadText(s: Status): string {
  const l = s.load!;
  return `Load ${l.kn.toFixed(2)} kN` + (l.hold_kn !== null ? ` · hold ${l.hold_kn} kN` : "") +
    (l.retract_kn !== null ? ` · retract ${l.retract_kn} kN` : "");
}

/** What the load guard did and what the operator may do now ("" while it did nothing). */
export function loadBanner(s: Status): string {
  const l = s.load!;
  if (l.action === "hold" && s.state === "held")
    return `Feed held: the load passed ${l.hold_kn} kN. Check the cutter, then resume or abort.`;
  if (l.action === "retract") return `Overload above ${l.retract_kn} kN: the run stopped on the path, the cutter lifts.`;
  if (l.action === "lifted")
    return `Overload above ${l.retract_kn} kN: the run was stopped and the cutter lifted off the wall. Check the cutter and the part before the next run.`;
  return "";
}

/** One line per process alarm: name, state, the input now, bounds and what it does. */
export function alarmLines(s: Status): { text: string; active: boolean }[] {
  return (s.alarms ?? []).map((a) => {
    const range = [a.low !== null ? `≥ ${a.low}` : "", a.high !== null ? `≤ ${a.high}` : ""].filter((x) => x).join(" and ");
    const value = typeof a.value === "number" ? ` ${a.value.toFixed(2)}${a.unit ? ` ${a.unit}` : ""}` : "";
    return { text: `${a.name}: ${a.active ? "ALARM" : "ok"}${value} (${range} ${a.unit}; ${a.reaction})`.replace(" ;", ";"), active: a.active };
  });
}

/** The EDM's live values as label/value rows. */
export function edmRows(s: Status): [string, string][] {
  const e = s.edm!;
  const depth = s.features?.edm;
  return [
    ["Condition", e.condition ? `E${e.condition}` : "none"],
    ["Generator", e.generator ? "on" : "off"],
    ["Gap", `${e.filtered_voltage_v.toFixed(1)} V` + (e.reference_v !== null ? ` (ref ${e.reference_v} V)` : "")],
    ["Discharge", e.gap_state + (e.retract_limit ? " · backing off at the path's end" : "")],
    ["Servo", `${(e.path_speed_mm_s * 1000).toFixed(1)} µm/s` + (e.backlog_mm > 0.0005 ? ` · ${e.backlog_mm.toFixed(3)} mm back` : "")],
    ["Jumps", `${e.jumps}` + (e.jumping ? ` · lifting ${e.jump_lift_mm.toFixed(2)} mm` : "")],
    ["Depth", depth ? `${depth.depth_mm.toFixed(3)} mm${depth.burning ? "" : " (last burn)"}` : "—"],
  ];
}

registerPanel({
  id: "load",
  mount(root) {
    root.append(el("div", { class: "loadline" }), el("meter", { min: "0", max: "1", value: "0" }), el("div", { class: "banner" }));
  },
  update(s, root) {
    if (!s.load) return false;
    root.querySelector(".loadline")!.textContent = loadText(s);
    const meter = root.querySelector("meter") as HTMLMeterElement;
    const top = Math.max(s.load.retract_kn ?? 0, s.load.hold_kn ?? 0, 1);
    meter.max = top;
    meter.high = s.load.hold_kn ?? top;
    meter.value = Math.max(0, s.load.kn);
    const banner = root.querySelector(".banner") as HTMLElement;
    banner.textContent = loadBanner(s);
    banner.hidden = banner.textContent === "";
    banner.dataset.testid = "load-banner";
    return true;
  },
});

registerPanel({
  id: "alarms",
  mount(root) {
    root.append(el("ul", { class: "alarms" }));
  },
  update(s, root) {
    const lines = alarmLines(s);
    const ul = root.querySelector("ul")!;
    ul.replaceChildren(...lines.map((l) => el("li", { class: l.active ? "error" : "" }, l.text)));
    return lines.length > 0;
  },
});

registerPanel({
  id: "edm",
  mount(root) {
    root.append(el("h3", {}, "EDM process"), el("table", { class: "grid edm" }));
  },
  update(s, root) {
    if (!s.edm) return false;
    const table = root.querySelector("table")!;
    table.replaceChildren(...edmRows(s).map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", {}, v))));
    return true;
  },
});
