// SPDX-License-Identifier: GPL-3.0-or-later
// Draws a registered dialog (or a panel's controls): its title, text, inputs and buttons; a button
// that asks for confirmation first shows the question with the values it will send ("Yes, …" /
// "Back") and sends the command with `confirmed: true` only after the second click
// (docs/hmi.md, "Dialogs").
import type { Dialog, DialogAction, DialogField } from "./registry";
import type { Status } from "./types";
import { button, el } from "./ui";

type Send = (kind: string, fields: Record<string, unknown>) => Promise<boolean>;
type Values = Record<string, number | string>;

/** The fields a button sends: its own, the inputs' values when it uses the form, the confirmation. */
export function actionFields(a: DialogAction, values: Values, confirmed: boolean): Record<string, unknown> {
  const out: Record<string, unknown> = { ...(a.fields ?? {}) };
  if (a.form) Object.assign(out, a.transform ? a.transform(values) : values);
  if (confirmed) out.confirmed = true;
  return out;
}

/** The question a confirmed button asks, with the inputs' values it sends. */
export function question(a: DialogAction, fields: DialogField[], values: Values): string {
  const shown = (k: string, v: unknown) => {
    const f = fields.find((x) => x.name === k);  // an input's own label and unit where it has one
    return f ? `${f.label.toLowerCase()} ${v}${f.unit ? ` ${f.unit}` : ""}` : `${k.replace(/_/g, " ")} ${v}`;
  };
  const detail = !a.form ? ""
    : a.transform ? Object.entries(a.transform(values)).map(([k, v]) => shown(k, v)).join(", ")
      : fields.map((f) => shown(f.name, values[f.name])).join(", ");
  return detail ? `${a.confirm} (${detail})` : (a.confirm ?? "");
}

/** The inputs of `fields` into a row; their values are kept in `values`. */
export function renderFields(fields: DialogField[], values: Values): HTMLElement {
  return el("div", { class: "row" }, ...fields.map((f) => {
    values[f.name] = f.value;
    let control: HTMLInputElement | HTMLSelectElement;
    if (f.options) {
      control = el("select", {}, ...f.options.map((o) => el("option", { value: o }, o)));
      control.value = String(f.value);
      control.addEventListener("change", () => (values[f.name] = control.value));
    } else {
      control = el("input", { type: "number", class: "num", value: String(f.value), step: "any" });
      control.addEventListener("change", () => (values[f.name] = Number(control.value)));
    }
    control.dataset.testid = `field-${f.name}`;
    return el("label", { class: "field" }, `${f.label} `, control, f.unit ? ` ${f.unit}` : "");
  }));
}

/** The buttons of `actions` into `row` (drawn again after a confirmation or "Back"). */
export function renderActions(row: HTMLElement, actions: DialogAction[], fields: DialogField[], values: Values, send: Send) {
  const draw = () => row.replaceChildren(...actions.map((a) => {
    const b = button(a.label, () => {
      if (!a.confirm) return void send(a.kind, actionFields(a, values, false));
      const yes = button(`Yes, ${a.label.toLowerCase()}`, () => {
        draw();
        void send(a.kind, actionFields(a, values, true));
      }, a.cls ?? "go");
      yes.dataset.testid = "confirm";
      row.replaceChildren(el("span", { class: "question" }, question(a, fields, values)), yes, button("Back", draw));
    }, a.cls ?? "");
    b.dataset.testid = `action-${a.kind}-${a.label.split(" ")[0].toLowerCase()}`;
    return b;
  }));
  draw();
}

/** Fills `dialog` for `d` and status `s`. */
export function renderDialog(dialog: HTMLDialogElement, d: Dialog, s: Status, send: Send) {
  const values: Values = {};
  const fields = d.fields?.(s) ?? [];
  const row = el("div", { class: "row" });
  const inputs = fields.length ? [renderFields(fields, values)] : [];
  renderActions(row, d.actions(s), fields, values, send);
  const more = d.more?.(s);
  const folded = more ? [el("details", { class: "dialog-more" }, el("summary", {}, more.summary), el("pre", {}, more.text))] : [];
  dialog.replaceChildren(el("h2", {}, d.title(s)), el("p", { class: "dialog-text" }, d.text(s)), ...folded, ...inputs, row);
}
