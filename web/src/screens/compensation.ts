// SPDX-License-Identifier: GPL-3.0-or-later
// The Compensation screen: each compensated axis' lead-screw (pitch-error) table as a table and a
// plot, its backlash beside it; the admin changes points, directions, start and interval (or, for
// a table in a LinuxCNC comp file, each point's position) while nothing runs (set-compensation:
// the profile's own checks, the tick takes the new table at rest).
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";
import type { Outcome } from "../types";
import { adminToken, outcomeLines } from "./parameters";

/** One axis as GET /api/v1/compensation gives it. */
export interface CompensationAxis {
  axis: string;
  unit: string;
  backlash: number;
  takeup_velocity: number;
  takeup_acceleration: number;
  table: { positions: number[]; forward: number[]; reverse: number[]; one_table: boolean } | null;
  comp_file: string | null;
  comp_file_type?: number;
  editable: boolean;
  max_points: number;
}

/**
 * What the admin typed: start, interval, and per point the errors moving in + and in −; for a
 * table in a comp file (points at any positions) each point's position instead of start and
 * interval.
 */
export interface TableInputs {
  start: string;
  interval: string;
  rows: { forward: string; reverse: string; position?: string }[];
}

function number(text: string, what: string): number | string {
  const t = text.trim();
  if (t === "") return `${what}: a value is needed`;
  const v = Number(t);
  return Number.isFinite(v) ? v : `${what}: "${t}" is not a number`;
}

/** The start and interval of a table's points (equal intervals), or 0 and 0 without a table. */
export function spacing(a: CompensationAxis): { start: number; interval: number } {
  const p = a.table?.positions ?? [];
  return { start: p[0] ?? 0, interval: p.length > 1 ? p[1] - p[0] : 0 };
}

/**
 * The set-compensation command for `inputs`, or why not in words (checked before anything is
 * sent; the profile's own checks follow on the controller). Start and interval go only when
 * they changed.
 */
export function compensationCommand(a: CompensationAxis, inputs: TableInputs): Record<string, unknown> | string {
  const n = inputs.rows.length;
  if (n < 1 || n > a.max_points) return `${a.axis}: a table has 1 to ${a.max_points} points (this one ${n})`;
  const forward: number[] = [];
  const reverse: number[] = [];
  for (const [i, r] of inputs.rows.entries()) {
    const f = number(r.forward, `${a.axis} point ${i + 1}, moving +`);
    if (typeof f === "string") return f;
    const b = number(r.reverse, `${a.axis} point ${i + 1}, moving −`);
    if (typeof b === "string") return b;
    forward.push(f);
    reverse.push(b);
  }
  const body: Record<string, unknown> = { kind: "set-compensation", axis: a.axis, forward, reverse };
  if (a.comp_file) return withPositions(a, inputs, body);
  const was = spacing(a);
  const start = number(inputs.start, `${a.axis} start`);
  if (typeof start === "string") return start;
  const interval = number(inputs.interval, `${a.axis} interval`);
  if (typeof interval === "string") return interval;
  if (!(interval > 0)) return `${a.axis} interval: must be greater than 0`;
  if (start !== was.start) body.start = start;
  if (interval !== was.interval) body.interval = interval;
  return body;
}

/**
 * A comp file's points: each row's position, increasing; sent only when they changed (the
 * controller keeps the file's positions otherwise).
 */
function withPositions(a: CompensationAxis, inputs: TableInputs, body: Record<string, unknown>): Record<string, unknown> | string {
  const positions: number[] = [];
  for (const [i, r] of inputs.rows.entries()) {
    const x = number(r.position ?? "", `${a.axis} point ${i + 1}, position`);
    if (typeof x === "string") return x;
    if (i > 0 && !(x > positions[i - 1])) return `${a.axis} point ${i + 1}, position: must be greater than point ${i}'s (${positions[i - 1]})`;
    positions.push(x);
  }
  const was = a.table?.positions ?? [];
  if (positions.length !== was.length || positions.some((x, i) => x !== was[i])) body.positions = positions;
  return body;
}

/**
 * The points of a table as they would be with `inputs`: each row's position for a comp file,
 * else start + k·interval (NaN where not a number).
 */
export function positionsOf(inputs: TableInputs): number[] {
  if (inputs.rows.some((r) => r.position !== undefined)) return inputs.rows.map((r) => Number(r.position));
  const s = Number(inputs.start);
  const d = Number(inputs.interval);
  return inputs.rows.map((_, k) => s + k * d);
}

/**
 * An SVG plot of a table: error (µm, up) over position, forward and reverse as two lines with
 * their points, zero and the ends labelled. A string of numbers and fixed words only.
 */
export function plotSvg(positions: number[], forward: number[], reverse: number[], unit: string, w = 520, h = 180): string {
  const pad = { l: 48, r: 10, t: 10, b: 24 };
  const ok = (v: number) => Number.isFinite(v);
  const xs = positions.filter(ok);
  const ys = [...forward, ...reverse, 0].filter(ok).map((v) => v * 1000);
  if (xs.length === 0) return `<svg xmlns="http://www.w3.org/2000/svg" width="${w}" height="${h}"></svg>`;
  const x0 = Math.min(...xs);
  const x1 = Math.max(...xs) > x0 ? Math.max(...xs) : x0 + 1;
  const y0 = Math.min(...ys);
  const y1 = Math.max(...ys) > y0 ? Math.max(...ys) : y0 + 1;
  const px = (x: number) => (pad.l + ((x - x0) / (x1 - x0)) * (w - pad.l - pad.r)).toFixed(1);
  const py = (y: number) => (h - pad.b - ((y - y0) / (y1 - y0)) * (h - pad.t - pad.b)).toFixed(1);
  const line = (values: number[], cls: string) => {
    const pts = positions.map((x, i) => [x, values[i] * 1000]).filter(([x, y]) => ok(x) && ok(y));
    const path = pts.map(([x, y]) => `${px(x)},${py(y)}`).join(" ");
    const dots = pts.map(([x, y]) => `<circle class="${cls}" cx="${px(x)}" cy="${py(y)}" r="2.5"/>`).join("");
    return `<polyline class="${cls}" fill="none" points="${path}"/>${dots}`;
  };
  const label = (x: number, y: number, text: string, anchor = "end") =>
    `<text x="${x}" y="${y}" text-anchor="${anchor}" font-size="10">${text}</text>`;
  return [
    `<svg xmlns="http://www.w3.org/2000/svg" width="${w}" height="${h}" class="comp-plot">`,
    `<line class="zero" x1="${pad.l}" x2="${w - pad.r}" y1="${py(0)}" y2="${py(0)}"/>`,
    line(forward, "forward"),
    line(reverse, "reverse"),
    label(pad.l - 4, Number(py(y1)) + 4, `${+y1.toFixed(1)} µm`),
    label(pad.l - 4, Number(py(y0)), `${+y0.toFixed(1)} µm`),
    label(pad.l, h - 6, `${+x0.toFixed(3)} ${unit}`, "start"),
    label(w - pad.r, h - 6, `${+x1.toFixed(3)} ${unit}`),
    `</svg>`,
  ].join("");
}

/**
 * The row "Add a point" appends: the last row's errors, and for a comp file a position one
 * interval (the last two points' distance, else 1) beyond the last.
 */
export function nextRow(rows: TableInputs["rows"], compFile: boolean): TableInputs["rows"][number] {
  const last = rows[rows.length - 1] ?? { forward: "0", reverse: "0", ...(compFile ? { position: "0" } : {}) };
  if (!compFile) return { forward: last.forward, reverse: last.reverse };
  const x = Number(last.position);
  const step = rows.length > 1 ? x - Number(rows[rows.length - 2].position) : 1;
  return { forward: last.forward, reverse: last.reverse, position: `${+(x + (step > 0 ? step : 1)).toFixed(6)}` };
}

/** One axis' section: backlash, the table of inputs, the plot, add/remove a point, apply. */
class AxisTable {
  private inputs: TableInputs;
  private readonly body = el("tbody");
  private readonly plot = el("div", { class: "plot" });
  private readonly result = el("pre", { class: "diagnostics" });
  private readonly start = el("input", { type: "number", step: "any", class: "num" });
  private readonly interval = el("input", { type: "number", step: "any", class: "num" });

  constructor(
    private readonly ctx: Context,
    private readonly a: CompensationAxis,
    private readonly reload: () => Promise<void>,
  ) {
    const s = spacing(a);
    const t = a.table;
    this.inputs = {
      start: `${s.start}`,
      interval: `${s.interval || 50}`,
      rows: (t?.forward ?? []).map((f, i) => ({
        forward: `${f}`,
        reverse: `${t?.reverse[i] ?? f}`,
        ...(a.comp_file ? { position: `${t?.positions[i] ?? 0}` } : {}),
      })),
    };
  }

  mount(root: HTMLElement) {
    const a = this.a;
    const source = a.comp_file
      ? `in the LinuxCNC comp file ${a.comp_file} (type ${a.comp_file_type ?? 0}: written back there, comment lines kept)`
      : a.table?.one_table
        ? "one table for both directions"
        : a.table
          ? "a table per direction"
          : "no pitch table yet";
    this.start.value = this.inputs.start;
    this.interval.value = this.inputs.interval;
    for (const [input, key] of [[this.start, "start"], [this.interval, "interval"]] as const)
      input.addEventListener("input", () => {
        this.inputs[key] = input.value;
        this.draw();
      });
    const head = el("tr", {}, ...["point", `position (${a.unit})`, `error moving + (${a.unit})`, `error moving − (${a.unit})`].map((h) => el("th", {}, h)));
    const section = el(
      "section",
      { class: "comp-axis", id: `comp-${a.axis}` },
      el("h3", {}, `Axis ${a.axis}`),
      el("p", { class: "hint" }, `Backlash ${a.backlash} ${a.unit} (Parameters screen), take-up ${a.takeup_velocity} ${a.unit}/s and ${a.takeup_acceleration} ${a.unit}/s²; ${source}.`),
      this.plot,
      a.comp_file ? "" : el("div", { class: "row" }, "start ", this.start, ` ${a.unit}, interval `, this.interval, ` ${a.unit}`),
      el("table", { class: "grid comp-table" }, el("thead", {}, head), this.body),
    );
    if (a.editable)
      section.append(
        el(
          "div",
          { class: "row" },
          button("Add a point", () => this.resize(1)),
          button("Remove the last point", () => this.resize(-1)),
          button("Apply table (admin)", () => void this.apply(), "primary"),
        ),
      );
    section.append(this.result);
    root.append(section);
    this.fill();
  }

  private resize(by: number) {
    const rows = this.inputs.rows;
    if (by > 0 && rows.length < this.a.max_points) rows.push(nextRow(rows, this.a.comp_file !== null));
    if (by < 0 && rows.length > 1) rows.pop();
    this.fill();
  }

  private fill() {
    const editable = this.a.editable;
    this.start.disabled = this.interval.disabled = !editable;
    this.body.replaceChildren(
      ...this.inputs.rows.map((r, i) => {
        const cell = (key: "forward" | "reverse") => {
          const input = el("input", { type: "number", step: "any", value: r[key], class: "num", "data-point": `${i}`, "data-dir": key });
          input.disabled = !editable;
          input.addEventListener("input", () => {
            r[key] = input.value;
            this.draw();
          });
          return el("td", {}, input);
        };
        if (r.position === undefined)
          return el("tr", {}, el("td", {}, `${i + 1}`), el("td", { class: "pos" }, ""), cell("forward"), cell("reverse"));
        const at = el("input", { type: "number", step: "any", value: r.position, class: "num", "data-point": `${i}`, "data-dir": "position" });
        at.disabled = !editable;
        at.addEventListener("input", () => {
          r.position = at.value;
          this.draw();
        });
        return el("tr", {}, el("td", {}, `${i + 1}`), el("td", {}, at), cell("forward"), cell("reverse"));
      }),
    );
    this.draw();
  }

  private draw() {
    const pos = positionsOf(this.inputs);
    this.body.querySelectorAll("td.pos").forEach((td, i) => (td.textContent = Number.isFinite(pos[i]) ? `${+pos[i].toFixed(4)}` : "—"));
    const values = (key: "forward" | "reverse") => this.inputs.rows.map((r) => Number(r[key]));
    this.plot.innerHTML = plotSvg(pos, values("forward"), values("reverse"), this.a.unit);
  }

  private async apply() {
    const body = compensationCommand(this.a, this.inputs);
    if (typeof body === "string") return this.show([body], "error");
    const o = await send(this.ctx, body);
    this.show(outcomeLines(o), o.status === 200 ? "note" : "error");
    if (o.status === 200) await this.reload();
  }

  private show(lines: string[], severity: "note" | "error") {
    this.result.textContent = lines.join("\n");
    this.result.className = `diagnostics ${severity}`;
    this.ctx.message(lines[0] ?? "", severity);
  }
}

let root: HTMLElement | undefined;
let tables: HTMLElement | undefined;
let token: HTMLInputElement | undefined;

/** POSTs a command with this screen's admin token (or the Parameters screen's). */
async function send(ctx: Context, body: Record<string, unknown>): Promise<Outcome & { status: number }> {
  const res = await fetch("/api/v1/commands", {
    method: "POST",
    headers: { Authorization: `Bearer ${token?.value || adminToken(ctx)}`, "Content-Type": "application/json" },
    body: JSON.stringify(body),
  });
  return { ...((await res.json()) as Outcome), status: res.status };
}

async function load(ctx: Context) {
  if (!root || !tables) return;
  const r = await ctx.api.get<{ profile: string; when: string; axes: CompensationAxis[] }>("compensation");
  const where = el("p", { class: "hint" }, `Written to ${r.profile} (comments kept), ${r.when}. Errors are actual − nominal; the tick takes a new table up from where its correction stands.`);
  tables.replaceChildren(where);
  if (r.axes.length === 0) tables.append(el("p", {}, "This machine has no compensated axis ([axis.<a>.compensation] in its profile)."));
  for (const a of r.axes) new AxisTable(ctx, a, () => load(ctx)).mount(tables);
}

registerScreen({
  id: "compensation",
  title: "Compensation",
  mount(r) {
    root = r;
    tables = el("div");
    token = el("input", { id: "comp-admin-token", type: "password", class: "token" });
    root.append(el("h2", {}, "Lead-screw compensation"), el("div", { class: "row" }, "Admin token: ", token), tables);
  },
  shown: (ctx) => void load(ctx),
});
