// SPDX-License-Identifier: GPL-3.0-or-later
// Screens, dialogs and panels plug in here: a new feature (power-fail recovery, retrace, tool
// check, EDM conditions) adds a file that calls registerScreen, registerDialog or registerPanel,
// and one import in main.ts.
import type { Api } from "./api";
import type { Machine, Status } from "./types";

/** What a screen or dialog may use. */
export interface Context {
  api: Api;
  machine: Machine;
  /** The newest status. */
  status(): Status | undefined;
  /** Sends a command and shows a refusal in the message line; resolves with whether it was taken. */
  send(kind: string, fields?: Record<string, unknown>): Promise<boolean>;
  /** A line in the message area. */
  message(text: string, severity?: "note" | "warning" | "error"): void;
}

/** A sub-screen behind a function key of the main screen. */
export interface Screen {
  id: string;
  /** The function key's label. */
  title: string;
  /** Builds the screen into `root` once. */
  mount(root: HTMLElement, ctx: Context): void;
  /** Every status while the screen is shown (and, if `always`, while it is not). */
  update?(s: Status, ctx: Context): void;
  /** Called when the screen is shown. */
  shown?(ctx: Context): void;
  /** A controller feature the screen needs: its key is hidden on a machine without it. */
  requires?: string;
}

/** A button of a dialog: a label and the command it sends. */
export interface DialogAction {
  label: string;
  kind: string;
  fields?: Record<string, unknown>;
  cls?: string;
  /** Asked in the dialog before it is sent ("Retract Z by 2 mm?"); sent with `confirmed: true`. */
  confirm?: string;
  /** The dialog's inputs' values go with the fields (through `transform` when given). */
  form?: boolean;
  transform?: (values: Record<string, number | string>) => Record<string, unknown>;
}

/** An input of a dialog (a number, or one of a few choices). */
export interface DialogField {
  name: string;
  label: string;
  value: number | string;
  /** Choices: a select; otherwise a number input. */
  options?: string[];
  unit?: string;
}

/** A modal dialog shown while the status asks for it (what the controller waits on). */
export interface Dialog {
  id: string;
  /** Whether this status needs the dialog; the first registered one that does is shown. */
  wants(s: Status): boolean;
  title(s: Status): string;
  text(s: Status): string;
  /** The buttons: a label and what it sends. */
  actions(s: Status): DialogAction[];
  /** Inputs shown above the buttons (kept while the dialog stays open). */
  fields?(s: Status): DialogField[];
  /** A part of the text folded under a summary line (opened with a click), if any. */
  more?(s: Status): { summary: string; text: string } | undefined;
}

/** A panel of the main screen's process column (the load, the alarms, the EDM's live values). */
export interface Panel {
  id: string;
  /** Builds the panel into `root` once. */
  mount(root: HTMLElement, ctx: Context): void;
  /** Every status: fills `root`; the panel is hidden while this returns false. */
  update(s: Status, root: HTMLElement, ctx: Context): boolean;
}

export const screens: Screen[] = [];
export const dialogs: Dialog[] = [];
export const panels: Panel[] = [];

export function registerScreen(s: Screen) {
  screens.push(s);
}

export function registerDialog(d: Dialog) {
  dialogs.push(d);
}

export function registerPanel(p: Panel) {
  panels.push(p);
}
