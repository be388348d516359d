// SPDX-License-Identifier: GPL-3.0-or-later
// Draws a registered dialog: its title, text, inputs and buttons; a button that asks for
// confirmation first shows the question in the dialog ("Yes, …" / "Back") and sends the command
// with `confirmed: true` only after the second click (docs/hmi.md, "Dialogs").
import type { Dialog, DialogAction, DialogField } from "./registry";
import type { Status } from "./types";
import { button, el } from "./ui";

/** The fields a button sends: its own, the inputs' values when it uses the form, the confirmation. */
export function actionFields(a: DialogAction, values: Record<string, number | string>, confirmed: boolean): Record<string, unknown> {
  const out: Record<string, unknown> = { ...(a.fields ?? {}) };
  if (a.form) Object.assign(out, values);
  if (confirmed) out.confirmed = true;
  return out;
}

function input(f: DialogField, values: Record<string, number | string>): HTMLElement {
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
}

/** Fills `dialog` for `d` and status `s`; `send` submits a command (resolves with whether it was taken). */
export function renderDialog(dialog: HTMLDialogElement, d: Dialog, s: Status,
  send: (kind: string, fields: Record<string, unknown>) => Promise<boolean>) {
  const values: Record<string, number | string> = {};
  const fields = d.fields?.(s) ?? [];
  const row = el("div", { class: "row" });
  const buttons = () => {
    row.replaceChildren(...d.actions(s).map((a) => {
      const b = button(a.label, () => {
        if (!a.confirm) return void send(a.kind, actionFields(a, values, false));
        const yes = button(`Yes, ${a.label.toLowerCase()}`, () => {
          buttons();
          void send(a.kind, actionFields(a, values, true));
        }, a.cls ?? "go");
        yes.dataset.testid = "confirm";
        // What the inputs say goes into the question: the operator confirms the values sent.
        const detail = a.form ? fields.map((f) => `${f.label.toLowerCase()} ${values[f.name]}${f.unit ? ` ${f.unit}` : ""}`).join(", ") : "";
        row.replaceChildren(el("span", { class: "question" }, detail ? `${a.confirm} (${detail})` : a.confirm), yes, button("Back", buttons));
      }, a.cls ?? "");
      b.dataset.testid = `action-${a.kind}-${a.label.split(" ")[0].toLowerCase()}`;
      return b;
    }));
  };
  buttons();
  dialog.replaceChildren(el("h2", {}, d.title(s)), el("p", { class: "dialog-text" }, d.text(s)),
    ...(fields.length ? [el("div", { class: "row" }, ...fields.map((f) => input(f, values)))] : []), row);
}
