// SPDX-License-Identifier: GPL-3.0-or-later
// The Cut chart screen of a plasma table: the materials of its cut chart (number, name, thickness,
// process, kerf, feed, pierce height and delay, cut height, arc voltage, current) with the one
// selected for programs that select none (M194 P<n> selects in a program) marked; an operator
// selects a material, an admin edits one (checked on the page first: numbers, cut height at most
// the pierce height, a process word; the store's own checks follow) or adds or removes one. Every
// change is one audited transaction of the chart's SQLite store (GET/POST /api/v1/cutchart).
import { registerScreen, type Context } from "../registry";
import { button, el } from "../ui";

/** One material as GET /api/v1/cutchart gives it. */
export interface Material {
  number: number;
  name: string;
  thickness_mm: number;
  process: string;
  kerf_width_mm: number;
  feed_mm_min: number;
  pierce_height_mm: number;
  pierce_delay_s: number;
  cut_height_mm: number;
  arc_voltage_v: number;
  amperage_a: number;
  puddle_height_mm: number;
  puddle_delay_s: number;
  /** Oxy-fuel: the preheat's time (0: the profile's); absent in an older server's answer. */
  preheat_s?: number;
  [field: string]: number | string | undefined;
}

/** One change as the chart's audit keeps it. */
export interface ChartChange {
  at_utc: string;
  interface: string;
  reason: string;
  what: string;
  old: string;
  new: string;
}

/** GET /api/v1/cutchart's answer. */
export interface CutChart {
  store: string;
  selected: number;
  fields: { name: string; required: boolean }[];
  materials: Material[];
  audit: ChartChange[];
}

/** The table's header, in materialCells()' order. */
export const chartHeader = ["#", "material", "mm", "process", "kerf mm", "feed mm/min", "pierce mm / s", "cut mm", "arc V", "A"];

/** A material's cells in chartHeader's order ("auto" for an arc voltage of 0: sampled). */
export function materialCells(m: Material): string[] {
  return [
    `${m.number}`,
    m.name,
    `${m.thickness_mm}`,
    m.process,
    `${m.kerf_width_mm}`,
    `${m.feed_mm_min}`,
    `${m.pierce_height_mm} / ${m.pierce_delay_s}` + (m.process === "oxy-fuel" ? ` · preheat ${m.preheat_s ? `${m.preheat_s} s` : "profile's"}` : ""),
    `${m.cut_height_mm}`,
    m.arc_voltage_v > 0 ? `${m.arc_voltage_v}` : "auto",
    `${m.amperage_a}`,
  ];
}

/** Whether a token of `role` may change the chart (an operator only selects). */
export function mayEdit(role: string | undefined): boolean {
  return role === "admin";
}

/** The body that selects material `n` (0: none) for programs that select none. */
export function selectBody(n: number): Record<string, unknown> {
  return { action: "select", material: n };
}

/** The fields an admin types, with their bounds (the store's checks, repeated on the page). */
const bounds: Record<string, [number, number, boolean]> = {
  thickness_mm: [0, 500, false],
  kerf_width_mm: [0, 20, false],
  feed_mm_min: [0, 100000, false],
  pierce_height_mm: [0, 100, false],
  pierce_delay_s: [0, 600, true],
  cut_height_mm: [0, 100, false],
  arc_voltage_v: [0, 1000, true],
  amperage_a: [0, 2000, true],
  puddle_height_mm: [0, 100, true],
  puddle_delay_s: [0, 600, true],
  preheat_s: [0, 600, true],
};

/** The fields of the edit form, in the chart's order. */
export const editFields = ["number", "name", "thickness_mm", "process", ...Object.keys(bounds).filter((k) => k !== "thickness_mm")];

/**
 * The set body for what the admin typed (every field; `inputs` holds the typed text by field, the
 * material's own value where nothing was typed); or why not in words, naming the field.
 */
export function materialBody(base: Partial<Material>, inputs: Record<string, string>): Record<string, unknown> | string {
  const typed = (f: string) => (inputs[f] ?? (base[f] === undefined ? "" : `${base[f]}`)).trim();
  const out: Record<string, number | string> = {};
  const n = Number(typed("number"));
  if (typed("number") === "" || !Number.isInteger(n) || n < 1 || n > 99999) return `number: a whole number from 1 to 99999, not "${typed("number")}"`;
  out.number = n;
  const name = typed("name");
  if (name === "") return "name: a material needs a name";
  out.name = name;
  const process = typed("process");
  if (process !== "plasma" && process !== "oxy-fuel") return `process: plasma or oxy-fuel, not "${process}"`;
  out.process = process;
  for (const [f, [lo, hi, zero]] of Object.entries(bounds)) {
    const t = f === "preheat_s" && typed(f) === "" ? "0" : typed(f);  // a chart from before the preheat: none
    const v = Number(t);
    if (t === "" || !Number.isFinite(v)) return `${f}: "${t}" is not a number`;
    if ((zero ? v < lo : v <= lo) || v > hi) return `${f}: ${v} is not ${zero ? "from" : "above"} ${lo}${zero ? " to" : " and at most"} ${hi}`;
    out[f] = v;
  }
  if ((out.cut_height_mm as number) > (out.pierce_height_mm as number))
    return `cut_height_mm: ${out.cut_height_mm} is above the pierce height ${out.pierce_height_mm}`;
  if ((out.puddle_delay_s as number) > 0 && out.puddle_height_mm === 0) return "puddle_delay_s: a puddle delay needs a puddle height";
  if ((out.preheat_s as number) > 0 && out.process === "plasma") return "preheat_s: a plasma material has no preheat (oxy-fuel only)";
  return { action: "set", material: out };
}

/** The question asked before material `n` is removed. */
export function removeQuestion(m: Material): string {
  return `Remove material ${m.number} (${m.name}) from the cut chart? Programs that select it (M194 P${m.number}) will no longer open.`;
}

/** A change of the audit as one line: "when interface what old → new". */
export function changeLine(c: ChartChange): string {
  return `${c.at_utc} ${c.interface} ${c.what}: ${c.old === "" ? "(none)" : c.old} → ${c.new === "" ? "(none)" : c.new}`;
}

let body: HTMLElement | undefined;
let note: HTMLElement | undefined;
let editor: HTMLElement | undefined;
let result: HTMLElement | undefined;
let changes: HTMLElement | undefined;
let token: HTMLInputElement | undefined;
let unlockRow: HTMLElement | undefined;
let adminToken = "";
let chart: CutChart | undefined;

function show(ctx: Context, text: string, severity: "note" | "error") {
  if (!result) return;
  result.textContent = text;
  result.className = `diagnostics ${severity}`;
  ctx.message(text, severity);
}

async function roleOf(t: string): Promise<string | undefined> {
  const res = await fetch("/api/v1/server", { headers: { Authorization: `Bearer ${t}` } });
  return res.ok ? ((await res.json()) as { role?: string }).role : undefined;
}

async function post(ctx: Context, b: Record<string, unknown>, t: string, done: string) {
  const res = await fetch("/api/v1/cutchart", {
    method: "POST",
    headers: { Authorization: `Bearer ${t}`, "Content-Type": "application/json" },
    body: JSON.stringify(b),
  });
  const answer = (await res.json()) as CutChart & { error?: string };
  if (!res.ok) return show(ctx, answer.error ?? `${res.status}`, "error");
  show(ctx, done, "note");
  render(ctx, answer);
}

function edit(ctx: Context, m: Partial<Material>) {
  if (!editor) return;
  const inputs: Record<string, string> = {};
  const rows = editFields.map((f) => {
    const value = m[f] === undefined ? "" : `${m[f]}`;
    const input =
      f === "process"
        ? el("select", { "data-field": f }, el("option", { value: "plasma" }, "plasma"), el("option", { value: "oxy-fuel" }, "oxy-fuel"))
        : el("input", { type: f === "name" ? "text" : "number", step: "any", class: f === "name" ? "" : "num", "data-field": f });
    input.value = value || (f === "process" ? "plasma" : "");
    inputs[f] = input.value;
    input.addEventListener("input", () => (inputs[f] = input.value));
    input.addEventListener("change", () => (inputs[f] = input.value));
    if (f === "number" && m.number !== undefined) (input as HTMLInputElement).readOnly = true;
    return el("tr", {}, el("th", {}, f), el("td", {}, input));
  });
  editor.replaceChildren(
    el("h3", {}, m.number === undefined ? "New material" : `Material ${m.number}`),
    el("table", { class: "grid", id: "material-form" }, el("tbody", {}, ...rows)),
    el(
      "div",
      { class: "row" },
      button("Apply (admin)", () => {
        const b = materialBody(m, inputs);
        if (typeof b === "string") return show(ctx, b, "error");
        void post(ctx, b, adminToken, `material ${(b.material as Material).number} stored`);
      }, "primary"),
      button("Back", () => editor?.replaceChildren()),
    ),
  );
}

function confirmRemove(ctx: Context, m: Material) {
  editor?.replaceChildren(
    el("p", { id: "remove-question" }, removeQuestion(m)),
    el(
      "div",
      { class: "row" },
      button(`Yes, remove ${m.number}`, () => void post(ctx, { action: "remove", material: m.number }, adminToken, `material ${m.number} removed`), "primary"),
      button("Back", () => editor?.replaceChildren()),
    ),
  );
}

function render(ctx: Context, c: CutChart) {
  if (!body || !note || !editor || !changes) return;
  chart = c;
  if (unlockRow) unlockRow.style.display = adminToken !== "" ? "none" : "";
  note.textContent =
    `From ${c.store}. M194 P<n> selects a material in a program; programs that select none cut with the selected one` +
    (c.selected ? ` (${c.selected}).` : " (none selected).");
  body.replaceChildren(
    ...c.materials.map((m) => {
      const tr = el("tr", {}, ...materialCells(m).map((t) => el("td", {}, t)));
      tr.dataset.material = `${m.number}`;
      tr.classList.toggle("active", m.number === c.selected);
      const actions = el("td", {}, button(m.number === c.selected ? "Selected" : "Select", () => void post(ctx, selectBody(m.number), ctx.api.token, `material ${m.number} selected`)));
      if (adminToken) actions.append(button("Edit", () => edit(ctx, m)), button("Remove", () => confirmRemove(ctx, m)));
      tr.append(actions);
      return tr;
    }),
  );
  editor.replaceChildren(...(adminToken ? [button("New material (admin)", () => edit(ctx, { process: "plasma", puddle_height_mm: 0, puddle_delay_s: 0, preheat_s: 0, arc_voltage_v: 0 }))] : []));
  changes.textContent = c.audit.slice(-8).map(changeLine).join("\n");
}

async function load(ctx: Context) {
  try {
    render(ctx, await ctx.api.get<CutChart>("cutchart"));
  } catch (e) {
    if (note) note.textContent = `This machine has no cut chart (${(e as Error).message}).`;
    body?.replaceChildren();
    if (unlockRow) unlockRow.style.display = "none";
  }
}

async function unlock(ctx: Context) {
  const t = token?.value || ctx.api.token;
  if (mayEdit(await roleOf(t))) {
    adminToken = t;
    if (chart) render(ctx, chart);
    return;
  }
  show(ctx, "Only an admin's token may change the cut chart: an operator selects a material.", "error");
}

registerScreen({
  id: "cutchart",
  title: "Cut chart",
  mount(root, ctx) {
    body = el("tbody");
    note = el("p", { class: "hint" });
    editor = el("div", { id: "material-editor" });
    result = el("pre", { class: "diagnostics", id: "cutchart-result" });
    changes = el("pre", { class: "hint", id: "cutchart-changes" });
    token = el("input", { id: "chart-admin-token", type: "password", class: "token" });
    unlockRow = el("div", { class: "row" }, "Admin token: ", token, button("Edit (admin)", () => void unlock(ctx)));
    const head = el("tr", {}, ...chartHeader.map((h) => el("th", {}, h)), el("th", {}, ""));
    root.append(el("h2", {}, "Cut chart"), note, unlockRow, el("table", { class: "grid", id: "cutchart" }, el("thead", {}, head), body), editor, result, el("h3", {}, "Last changes"), changes);
  },
  async shown(ctx) {
    if (!adminToken && mayEdit(await roleOf(ctx.api.token))) adminToken = ctx.api.token;
    await load(ctx);
  },
});
