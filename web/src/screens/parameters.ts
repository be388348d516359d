// SPDX-License-Identifier: GPL-3.0-or-later
// Machine parameters (the profile's editable keys: axis limits): shown to everyone, changed with
// the admin token while nothing runs; the profile's own messages when a value is refused.
import type { Context } from "../registry";
import type { Outcome } from "../types";
import { button, el } from "../ui";

/** One editable parameter as GET /api/v1/parameters gives it. */
export interface Parameter {
  key: string;
  value: number;
  unit: string;
  what: string;
}

/** The values of `inputs` that differ from `params` (what a set-parameters command sends). */
export function changedValues(params: Parameter[], inputs: Record<string, string>): Record<string, number> | string {
  const out: Record<string, number> = {};
  for (const p of params) {
    const text = (inputs[p.key] ?? "").trim();
    if (text === "") return `${p.key}: a value is needed`;
    const v = Number(text);
    if (!Number.isFinite(v)) return `${p.key}: "${text}" is not a number`;
    if (v !== p.value) out[p.key] = v;
  }
  return out;
}

/** The admin's token, typed on the Parameters screen (the page itself holds the operator's). */
export function adminToken(ctx: Context): string {
  return (document.getElementById("admin-token") as HTMLInputElement | null)?.value || ctx.api.token;
}

/** POSTs a command with the admin token; resolves with the status and the answer. */
export async function adminCommand(ctx: Context, body: Record<string, unknown>): Promise<Outcome & { status: number }> {
  const res = await fetch("/api/v1/commands", {
    method: "POST",
    headers: { Authorization: `Bearer ${adminToken(ctx)}`, "Content-Type": "application/json" },
    body: JSON.stringify(body),
  });
  return { ...((await res.json()) as Outcome), status: res.status };
}

/** The answer in words: the message, then each diagnostic (`file:line:col: error: …`) it does not quote. */
export function outcomeLines(o: Outcome): string[] {
  const lines = [o.message ?? o.error ?? ""];
  for (const d of o.diagnostics ?? []) if (!lines[0].includes(d.text)) lines.push(d.text);
  return lines.filter((l) => l !== "");
}

/** The machine-parameters section of the Parameters screen. */
export class ParametersPanel {
  private params: Parameter[] = [];
  private inputs = new Map<string, HTMLInputElement>();
  private readonly body = el("tbody");
  private readonly result = el("pre", { class: "diagnostics", id: "parameters-result" });
  private readonly where = el("p", { class: "hint" });

  constructor(private readonly ctx: Context) {}

  mount(root: HTMLElement) {
    const head = el("tr", {}, ...["parameter", "value", "unit", ""].map((h) => el("th", {}, h)));
    root.append(
      el("h2", {}, "Machine parameters"),
      this.where,
      el("table", { class: "grid", id: "parameters" }, el("thead", {}, head), this.body),
      el("div", { class: "row" }, button("Apply changes (admin)", () => void this.apply(), "primary"), button("Revert", () => this.fill())),
      this.result,
    );
  }

  async load() {
    const r = await this.ctx.api.get<{ profile: string; when: string; parameters: Parameter[] }>("parameters");
    this.params = r.parameters;
    this.where.textContent = `Written to ${r.profile} (comments kept), ${r.when}. Each value is checked by the profile's own rules.`;
    this.fill();
  }

  private fill() {
    this.inputs.clear();
    this.body.replaceChildren(
      ...this.params.map((p) => {
        const input = el("input", { type: "number", step: "any", value: `${p.value}`, class: "num", "data-key": p.key });
        this.inputs.set(p.key, input);
        return el("tr", {}, el("td", {}, p.key), el("td", {}, input), el("td", {}, p.unit), el("td", { class: "hint" }, p.what));
      }),
    );
  }

  private async apply() {
    const values: Record<string, string> = {};
    for (const [k, i] of this.inputs) values[k] = i.value;
    const changed = changedValues(this.params, values);
    if (typeof changed === "string") return this.show([changed], "error");
    if (Object.keys(changed).length === 0) return this.show(["nothing changed"], "note");
    const o = await adminCommand(this.ctx, { kind: "set-parameters", values: changed });
    this.show(outcomeLines(o), o.status === 200 ? "note" : "error");
    if (o.status !== 200) return;
    await this.load();
    Object.assign(this.ctx.machine, await this.ctx.api.get("machine"));  // jog speeds, the soft-limit box
  }

  private show(lines: string[], severity: "note" | "error") {
    this.result.textContent = lines.join("\n");
    this.result.className = `diagnostics ${severity}`;
    this.ctx.message(lines[0] ?? "", severity);
  }
}
