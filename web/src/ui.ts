// SPDX-License-Identifier: GPL-3.0-or-later
// Small DOM helpers and number formats shared by the screens.

/** Creates an element with a class, text and children. */
export function el<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Record<string, string> = {},
  ...children: (Node | string)[]
): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "class") e.className = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

/** A button that runs `action` on click (mouse alone is enough for every screen). */
export function button(label: string, action: () => void, cls = ""): HTMLButtonElement {
  const b = el("button", { class: cls, type: "button" }, label);
  b.addEventListener("click", action);
  return b;
}

/** A coordinate as a DRO shows it: sign, 3 decimals (mm). */
export function coord(v: number | undefined): string {
  if (v === undefined || !Number.isFinite(v)) return "—";
  const r = Math.abs(v) < 0.0005 ? 0 : v;
  return (r >= 0 ? "+" : "") + r.toFixed(3);
}

/** A percentage for overrides: 1.2 → "120 %". */
export function percent(v: number): string {
  return `${Math.round(v * 100)} %`;
}

/** The offsets of a status in words, for the DRO's work column: "G55 X+10.000 Y+20.000 · G92 X+1.000". */
export function offsetsText(
  o: { system: string; g5x: Record<string, number>; g92: Record<string, number>; tool: Record<string, number>; xy_rotation_deg: number },
  axes: string[],
): string {
  const part = (name: string, p: Record<string, number>) => {
    const set = axes.filter((a) => (p[a] ?? 0) !== 0).map((a) => `${a}${coord(p[a])}`);
    return set.length ? `${name} ${set.join(" ")}` : "";
  };
  const parts = [part(o.system, o.g5x) || o.system, part("G92", o.g92), part("tool", o.tool)];
  if (o.xy_rotation_deg !== 0) parts.push(`R${o.xy_rotation_deg}°`);
  return parts.filter((p) => p).join(" · ");
}

/** The first line of a listing window of `size` lines for `line`: a quarter of it before. */
export function windowStart(line: number, size: number): number {
  return Math.max(1, line - Math.floor(size / 4));
}

/** Whether `line` (0: none) lies outside the window [from, from + count) of a file that has more
 * lines after it when `more`, so that another window must be loaded. */
export function outsideWindow(line: number, from: number, count: number, more: boolean): boolean {
  return line > 0 && (line < from || (line >= from + count && more));
}

/** How one of the top bar's buttons shows itself: pressed when what it sets is in force, disabled
 * when it has nothing to do (the title says why, so a click never answers "nothing to do"). */
export interface ButtonLook {
  on: boolean;
  disabled: boolean;
  title: string;
}

/** The top bar's power and mode buttons for a machine state ("e-stopped", "off", "idle",
 * "running", "held", "stopped", "faulted") and mode ("manual", "mdi", "auto"). */
export function topBarLooks(state: string, mode: string): Record<string, ButtonLook> {
  const on = state === "idle" || state === "running" || state === "held" || state === "stopped";
  const busy = state === "running" || state === "held" || state === "stopped";
  const look = (pressed: boolean, why: string): ButtonLook => ({ on: pressed, disabled: why !== "", title: why });
  const looks: Record<string, ButtonLook> = {
    estop: look(state === "e-stopped", ""),
    reset: look(false, state === "e-stopped" || state === "faulted" ? "" : "nothing to reset: the machine is neither e-stopped nor faulted"),
    "machine-on": look(on, on ? "the machine is on" : state === "e-stopped" ? "reset the e-stop first"
      : state === "faulted" ? "reset the fault first" : ""),
    "machine-off": look(state === "off", on ? "" : "the machine is off"),
  };
  for (const m of ["manual", "mdi", "auto"])
    looks[m] = look(mode === m, mode === m ? `in ${m.toUpperCase()} mode` : busy ? "the mode changes while nothing runs" : "");
  return looks;
}
