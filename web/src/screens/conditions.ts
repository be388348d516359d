// SPDX-License-Identifier: GPL-3.0-or-later
// The Machining conditions screen: an EDM's conditions ([[edm.condition]] of its profile) as a
// table — number, on/off time, peak current, voltage, polarity, servo reference, jump and orbit —
// with the one the generator runs now (the status' edm.condition) highlighted live. An admin
// edits a condition's fields while nothing runs (set-conditions: the profile's own checks, the
// tick takes the new values at rest), adds a condition as a copy of another (add-condition) and
// deletes one after a confirmation (delete-condition); an operator sees them read-only. Anyone
// plans a roughing-to-finishing sequence for an electrode (its frontal area, the finish, the
// undersize: GET /api/v1/edm-sequence), sees its steps and takes its program.
import { registerScreen, type Context } from "../registry";
import type { Outcome, Status } from "../types";
import { button, el } from "../ui";
import { outcomeLines } from "./parameters";

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
  [field: string]: number | string;
}

/** A field the admin may change, as GET /api/v1/conditions lists them. */
export interface ConditionField {
  key: string;
  unit: string;
  what: string;
  /** The words of a choice ("+", "-"); absent for a number. */
  choices?: string[];
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

/** Whether a token of `role` (GET /api/v1/server's) may change the conditions. */
export function mayEdit(role: string | undefined): boolean {
  return role === "admin";
}

/**
 * The set-conditions command for what the admin typed into condition `c`'s fields, with only the
 * fields that changed; or why not in words (checked before anything is sent; the profile's own
 * checks follow on the controller).
 */
export function conditionCommand(c: Condition, fields: ConditionField[], inputs: Record<string, string>): Record<string, unknown> | string {
  const values: Record<string, number | string> = {};
  for (const f of fields) {
    const typed = (inputs[f.key] ?? `${c[f.key]}`).trim();
    if (f.choices) {
      if (!f.choices.includes(typed)) return `E${c.number} ${f.key}: one of ${f.choices.join(" ")}`;
      if (typed !== c[f.key]) values[f.key] = typed;
      continue;
    }
    if (typed === "") return `E${c.number} ${f.key}: a value is needed`;
    const v = Number(typed);
    if (!Number.isFinite(v)) return `E${c.number} ${f.key}: "${typed}" is not a number`;
    if (v !== c[f.key]) values[f.key] = v;
  }
  if (Object.keys(values).length === 0) return `E${c.number}: nothing changed`;
  return { kind: "set-conditions", condition: c.number, values };
}

/**
 * The add-condition command for a new condition numbered `typed`, a copy of condition `from` (the
 * admin's choice; the server copies the one below when it is absent); or why not in words.
 */
export function addConditionCommand(numbers: number[], typed: string, from: number | undefined): Record<string, unknown> | string {
  const t = typed.trim();
  const n = Number(t);
  if (t === "" || !Number.isInteger(n) || n < 1 || n > 99) return `A condition's number is a whole number from 1 to 99, not "${t}"`;
  if (numbers.includes(n)) return `E${n} exists already: edit it instead`;
  if (from !== undefined && !numbers.includes(from)) return `There is no E${from} to copy`;
  return from === undefined ? { kind: "add-condition", condition: n } : { kind: "add-condition", condition: n, from };
}

/** The question asked before condition `n` is deleted (the delete is sent on the second click). */
export function deleteQuestion(n: number): string {
  return `Delete E${n} from the profile? Programs that select it (M180 P${n}) will no longer open.`;
}

/** One step of a condition sequence as GET /api/v1/edm-sequence gives it. */
export interface SequenceStep {
  condition: number;
  peak_current_a: number;
  ra_um: number;
  vdi: number;
  side_gap_mm: number;
  orbit_mm: number;
  wall_mm: number;
  allowance_mm: number;
  removal_mm3_min: number;
  wear_ratio: number;
  orbit_limited: boolean;
}

/** What the operator types to plan a sequence. */
export interface SequenceInputs {
  area: string;
  finish: string;
  undersize: string;
  surface: string;
  depth: string;
}

/**
 * The query of GET /api/v1/edm-sequence for what was typed, or why not in words (checked before
 * anything is sent; the table's own limits come from the controller). The surface and the depth
 * are optional: with a depth the answer carries the program.
 */
export function sequenceQuery(i: SequenceInputs): string | { error: string } {
  const q = new URLSearchParams();
  const positive = (name: string, typed: string, what: string): string | undefined => {
    const t = typed.trim();
    const v = Number(t);
    if (t === "" || !Number.isFinite(v) || v <= 0) return `${what} must be a number above 0, not "${t}"`;
    q.set(name, t);
    return undefined;
  };
  const area = positive("area", i.area, "The electrode's frontal area (mm²)");
  if (area) return { error: area };
  const finish = i.finish.trim();
  if (!/^(ra)?\d+(\.\d+)?$|^vdi\d+(\.\d+)?$/i.test(finish)) return { error: `The finish is an Ra in µm (0.8) or a VDI class (VDI18), not "${finish}"` };
  q.set("finish", finish);
  const undersize = positive("undersize", i.undersize, "The undersize per side (mm)");
  if (undersize) return { error: undersize };
  if (i.depth.trim() !== "") {
    const depth = positive("depth", i.depth, "The depth (mm)");
    if (depth) return { error: depth };
    const s = i.surface.trim() === "" ? "0" : i.surface.trim();
    if (!Number.isFinite(Number(s))) return { error: `The surface is a position in mm, not "${s}"` };
    q.set("surface", s);
  }
  return q.toString();
}

/** The sequence table's header: what each column of sequenceCells() shows. */
export const sequenceHeader = ["step", "E", "peak A", "Ra µm (VDI)", "side gap mm", "orbit mm", "wall mm", "left mm", "removal mm³/min", "wear %"];

/** A step's cells, in sequenceHeader's order (the orbit "-" for a condition without one). */
export function sequenceCells(k: number, s: SequenceStep): string[] {
  const orbit = s.orbit_mm > 0 ? `${s.orbit_mm.toFixed(4)}${s.orbit_limited ? " (its largest)" : ""}` : "-";
  return [
    `${k + 1}`,
    `E${s.condition}`,
    `${s.peak_current_a}`,
    `${s.ra_um} (${s.vdi})`,
    s.side_gap_mm.toFixed(4),
    orbit,
    s.wall_mm.toFixed(4),
    s.allowance_mm.toFixed(4),
    `${s.removal_mm3_min}`,
    `${Math.round(s.wear_ratio * 100)}`,
  ];
}

interface SequenceAnswer {
  steps: SequenceStep[];
  text: string;
  program?: string;
  message?: string;
}

interface ConditionsAnswer {
  profile: string;
  when: string;
  fields: ConditionField[];
  conditions: Condition[];
}

let body: HTMLElement | undefined;
let note: HTMLElement | undefined;
let editor: HTMLElement | undefined;
let result: HTMLElement | undefined;
let token: HTMLInputElement | undefined;
let unlockRow: HTMLElement | undefined;
let adderRow: HTMLElement | undefined;
let shown = -1;
/** The admin's token once checked (the page's own when it is an admin's); "" while read-only. */
let adminToken = "";
let answer: ConditionsAnswer | undefined;
let sequenceBody: HTMLElement | undefined;
let sequenceProgram: HTMLElement | undefined;

function highlight(active: number) {
  if (!body || active === shown) return;
  shown = active;
  body.querySelectorAll("tr").forEach((tr) => tr.classList.toggle("active", Number(tr.dataset.condition) === active));
}

function show(ctx: Context, lines: string[], severity: "note" | "error") {
  if (!result) return;
  result.textContent = lines.join("\n");
  result.className = `diagnostics ${severity}`;
  ctx.message(lines[0] ?? "", severity);
}

/** The role of `t` (GET /api/v1/server answers with the token's role), undefined when refused. */
async function roleOf(t: string): Promise<string | undefined> {
  const res = await fetch("/api/v1/server", { headers: { Authorization: `Bearer ${t}` } });
  return res.ok ? ((await res.json()) as { role?: string }).role : undefined;
}

async function apply(ctx: Context, body: Record<string, unknown>) {
  const res = await fetch("/api/v1/commands", {
    method: "POST",
    headers: { Authorization: `Bearer ${adminToken}`, "Content-Type": "application/json" },
    body: JSON.stringify(body),
  });
  const o = { ...((await res.json()) as Outcome), status: res.status };
  show(ctx, outcomeLines(o), o.status === 200 ? "note" : "error");
  if (o.status === 200) await load(ctx, Number(body.condition));
}

/** The admin's form for condition `c`: a line per field (a number or the choice's words). */
function edit(ctx: Context, c: Condition) {
  if (!editor || !answer) return;
  const inputs: Record<string, string> = {};
  const rows = answer.fields.map((f) => {
    inputs[f.key] = `${c[f.key]}`;
    let input: HTMLInputElement | HTMLSelectElement;
    if (f.choices) {
      input = el("select", { "data-field": f.key }, ...f.choices.map((w) => el("option", { value: w }, w)));
    } else {
      input = el("input", { type: "number", step: "any", class: "num", "data-field": f.key });
    }
    input.value = inputs[f.key];
    input.addEventListener("input", () => (inputs[f.key] = input.value));
    input.addEventListener("change", () => (inputs[f.key] = input.value));
    return el("tr", {}, el("th", {}, f.key), el("td", {}, input), el("td", {}, f.unit), el("td", { class: "hint" }, f.what));
  });
  editor.replaceChildren(
    el("h3", {}, `Condition E${c.number}`),
    el("table", { class: "grid", id: "condition-form" }, el("tbody", {}, ...rows)),
    el(
      "div",
      { class: "row" },
      button(`Apply E${c.number} (admin)`, () => {
        const command = conditionCommand(c, answer?.fields ?? [], inputs);
        if (typeof command === "string") return show(ctx, [command], "error");
        void apply(ctx, command);
      }, "primary"),
    ),
  );
}

/** The question before condition `c` is deleted, in the editor: "Yes, delete" sends it, "Back" does not. */
function confirmDelete(ctx: Context, c: Condition) {
  if (!editor) return;
  editor.replaceChildren(
    el("p", { id: "delete-question" }, deleteQuestion(c.number)),
    el(
      "div",
      { class: "row" },
      button(`Yes, delete E${c.number}`, () => void apply(ctx, { kind: "delete-condition", condition: c.number }), "primary"),
      button("Back", () => editor?.replaceChildren()),
    ),
  );
}

/** The admin's row to add a condition: its number and the condition it copies. */
function adder(ctx: Context, conditions: Condition[]): HTMLElement {
  const numbers = conditions.map((c) => c.number);
  const number = el("input", { id: "new-condition", type: "number", step: "1", min: "1", max: "99", class: "num" });
  const from = el("select", { id: "new-condition-from" }, ...conditions.map((c) => el("option", { value: `${c.number}` }, `E${c.number}`)));
  from.value = `${numbers[numbers.length - 1] ?? ""}`;
  return el(
    "div",
    { class: "row", id: "condition-adder" },
    "New condition E",
    number,
    " a copy of ",
    from,
    button("Add (admin)", () => {
      const command = addConditionCommand(numbers, number.value, Number(from.value));
      if (typeof command === "string") return show(ctx, [command], "error");
      void apply(ctx, command);
    }),
  );
}

async function load(ctx: Context, selected = 0) {
  const r = await ctx.api.get<ConditionsAnswer>("conditions");
  if (!body || !note || !editor) return;
  answer = r;
  const empty = r.conditions.length === 0;
  if (unlockRow) unlockRow.style.display = empty || adminToken !== "" ? "none" : ""; // .row is a flex box: not `hidden`
  note.textContent = empty
    ? "This machine has no machining conditions (an EDM's [[edm.condition]] in its profile)."
    : `From ${r.profile}; M180 P<n> selects one in a program, M181 switches the generator off. The one in force is highlighted.` +
      (adminToken ? ` Choose a condition to change it (written to the profile, comments kept, ${r.when}).` : "");
  body.replaceChildren(
    ...r.conditions.map((c) => {
      const cells = conditionCells(c).map((t) => el("td", {}, t));
      const tr = el("tr", {}, ...cells);
      if (adminToken) tr.append(el("td", {}, button("Edit", () => edit(ctx, c)), button("Delete", () => confirmDelete(ctx, c))));
      tr.dataset.condition = `${c.number}`;
      return tr;
    }),
  );
  editor.replaceChildren();
  adderRow?.replaceChildren(...(adminToken && !empty ? [adder(ctx, r.conditions)] : []));
  const again = r.conditions.find((c) => c.number === selected);
  if (adminToken && again) edit(ctx, again);
  shown = -1;
  highlight(activeCondition(ctx.status()));
}

/** Plans the sequence for what was typed and shows its steps and its program. */
async function plan(ctx: Context, inputs: SequenceInputs) {
  const query = sequenceQuery(inputs);
  if (typeof query !== "string") return show(ctx, [query.error], "error");
  const res = await fetch(`/api/v1/edm-sequence?${query}`, { headers: { Authorization: `Bearer ${ctx.api.token}` } });
  const a = (await res.json()) as SequenceAnswer;
  if (!res.ok) return show(ctx, [a.message ?? `${res.status}`], "error");
  sequenceBody?.replaceChildren(...a.steps.map((s, k) => el("tr", {}, ...sequenceCells(k, s).map((t) => el("td", {}, t)))));
  if (sequenceProgram) sequenceProgram.textContent = a.program ?? "(give a depth for the program)";
  show(ctx, [`${a.steps.length} steps, E${a.steps[0]?.condition} to E${a.steps[a.steps.length - 1]?.condition}`], "note");
}

/** The sequence planner: area, finish, undersize (and the surface and depth for a program). */
function planner(ctx: Context): HTMLElement {
  const field = (id: string, placeholder: string) => el("input", { id, type: "text", class: "num", placeholder });
  const area = field("seq-area", "20");
  const finish = field("seq-finish", "VDI18");
  const undersize = field("seq-undersize", "0.08");
  const surface = field("seq-surface", "-20");
  const depth = field("seq-depth", "0.1");
  const inputs = (): SequenceInputs => ({ area: area.value, finish: finish.value, undersize: undersize.value, surface: surface.value, depth: depth.value });
  sequenceBody = el("tbody");
  sequenceProgram = el("pre", { id: "sequence-program", class: "diagnostics" });
  return el(
    "div",
    { id: "condition-sequence" },
    el("h3", {}, "Condition sequence"),
    el("div", { class: "row" }, "Area mm² ", area, " finish (Ra µm or VDI) ", finish, " undersize mm ", undersize),
    el("div", { class: "row" }, "Surface ", surface, " depth mm ", depth, button("Plan", () => void plan(ctx, inputs()), "primary"),
      button("Copy the program", () => void navigator.clipboard?.writeText(sequenceProgram?.textContent ?? ""))),
    el("table", { class: "grid", id: "sequence" }, el("thead", {}, el("tr", {}, ...sequenceHeader.map((h) => el("th", {}, h)))), sequenceBody),
    sequenceProgram,
  );
}

/** Edit mode when the typed token (or the page's) is an admin's. */
async function unlock(ctx: Context) {
  const t = token?.value || ctx.api.token;
  if (mayEdit(await roleOf(t))) {
    adminToken = t;
    return load(ctx);
  }
  show(ctx, ["Only an admin's token may change the conditions: they stay read-only."], "error");
}

registerScreen({
  id: "conditions",
  title: "Conditions",
  mount(root, ctx) {
    body = el("tbody");
    note = el("p", { class: "hint" });
    editor = el("div", { id: "condition-editor" });
    adderRow = el("div");
    result = el("pre", { class: "diagnostics", id: "conditions-result" });
    token = el("input", { id: "cond-admin-token", type: "password", class: "token" });
    unlockRow = el("div", { class: "row" }, "Admin token: ", token, button("Edit (admin)", () => void unlock(ctx)));
    const head = el("tr", {}, ...conditionHeader.map((h) => el("th", {}, h)), el("th", {}, ""));
    root.append(
      el("h2", {}, "Machining conditions"),
      note,
      unlockRow,
      el("table", { class: "grid", id: "conditions" }, el("thead", {}, head), body),
      adderRow,
      editor,
      result,
      planner(ctx),
    );
  },
  async shown(ctx) {
    if (!adminToken && mayEdit(await roleOf(ctx.api.token))) adminToken = ctx.api.token;
    await load(ctx);
  },
  update(s) {
    highlight(activeCondition(s));
  },
});
