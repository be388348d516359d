// SPDX-License-Identifier: GPL-3.0-or-later
// Screens and dialogs plug in here: a new feature (power-fail recovery, retrace, tool check, EDM
// conditions) adds a file that calls registerScreen or registerDialog, and one import in main.ts.
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
}

/** A modal dialog shown while the status asks for it (what the controller waits on). */
export interface Dialog {
  id: string;
  /** Whether this status needs the dialog; the first registered one that does is shown. */
  wants(s: Status): boolean;
  title(s: Status): string;
  text(s: Status): string;
  /** The buttons: a label and what it sends. */
  actions(s: Status): { label: string; kind: string; fields?: Record<string, unknown>; cls?: string }[];
}

export const screens: Screen[] = [];
export const dialogs: Dialog[] = [];

export function registerScreen(s: Screen) {
  screens.push(s);
}

export function registerDialog(d: Dialog) {
  dialogs.push(d);
}
