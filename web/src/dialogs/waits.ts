// SPDX-License-Identifier: GPL-3.0-or-later
// Dialogs for what the controller waits on: a manual tool change, M0/M1 and single block, feed
// hold, a sync point or a hand-fed axis, a fault, e-stop.
import { dialogs, registerDialog, type Dialog } from "../registry";
import type { Status } from "../types";

const abort = { label: "Abort", kind: "abort", cls: "danger" };

registerDialog({
  id: "tool-change",
  wants: (s) => s.wait === "manual-tool-change",
  title: (s) => `Tool change: T${s.prepared_tool}`,
  text: (s) => `Put tool T${s.prepared_tool} in the spindle, then confirm. (${s.wait_text})`,
  actions: () => [{ label: "Tool is in — continue", kind: "tool-changed", cls: "go" }, abort],
});

registerDialog({
  id: "program-stop",
  wants: (s) => s.state === "stopped",
  title: (s) =>
    s.stop_reason === "single-block" ? "Single block" : s.stop_reason === "optional-stop" ? "Optional stop (M1)" : "Program stop (M0)",
  text: (s) => `The program waits for ${s.wait_text || "cycle start"}.`,
  actions: () => [{ label: "Continue (cycle start)", kind: "cycle-start", cls: "go" }, abort],
});

registerDialog({
  id: "feed-hold",
  wants: (s) => s.state === "held",
  title: () => "Feed hold",
  text: (s) => `The machine stands on the path. ${s.wait_text}`,
  actions: () => [{ label: "Resume", kind: "resume", cls: "go" }, abort],
});

registerDialog({
  id: "sync-wait",
  wants: (s) => s.job.active && (s.wait === "hand-axis" || s.wait === "input" || s.wait === "interlock" || s.wait === "probe"),
  title: () => "The program waits",
  text: (s) => `Waiting for ${s.wait_text}.`,
  actions: () => [{ label: "Feed hold", kind: "feed-hold" }, abort],
});

registerDialog({
  id: "fault",
  wants: (s) => s.state === "faulted",
  title: () => "Fault",
  text: (s) => `${s.fault || "The machine faulted."} Remove the cause, then reset and switch the machine on.`,
  actions: () => [{ label: "Reset", kind: "reset", cls: "go" }],
});

/** The dialog a status asks for, if any: the first registered one that wants it. */
export function dialogFor(s: Status): Dialog | undefined {
  return dialogs.find((d) => d.wants(s));
}
